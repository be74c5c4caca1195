// rcm._rcm: the compiled part of the Python package rcm (python/rcm).
#include <pybind11/pybind11.h>

#include "bindings.h"

PYBIND11_MODULE(_rcm, module) {
  module.doc() =
      "rcm: the refractive index n of water from stereo images of a camera "
      "calibrated in air (the compiled bindings; import rcm).\n\n"
      "Conventions (docs/design.md, Sec. 4): camera frame x right, y down, "
      "z "
      "forward; the port normal is +z; pixel centers at integers; lengths in "
      "meters, angles in radians unless a name says degrees; cam1_from_cam0 "
      "maps points in cam0 (the left camera) into cam1.";
  // Order matters: classes used in signatures are registered first.
  rcm::python::BindCameras(module);
  rcm::python::BindRig(module);
  rcm::python::BindVirtualPinhole(module);
  rcm::python::BindCorrespondences(module);
  rcm::python::BindEstimators(module);
  rcm::python::BindEstimate(module);
  rcm::python::BindFrontEnd(module);
  rcm::python::BindSequence(module);
  rcm::python::BindBundle(module);
  rcm::python::BindSimulation(module);
  rcm::python::BindCalibration(module);
}
