// The binding areas of the module rcm._rcm, one source file each, and the
// small types they share.
#ifndef RCM_PYTHON_SRC_BINDINGS_H_
#define RCM_PYTHON_SRC_BINDINGS_H_

#include <pybind11/pybind11.h>

#include "rcm/camera/camera.h"
#include "rcm/camera/flat_port_geometry.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::python {

// One camera of a rig as Python sees it: the in-air lens and the flat port
// in front of it (the paper's thin port when the rig has none).
struct RigCamera {
  Camera camera;
  FlatPort port;
};

// A StereoRig argument that may also be the name of a reference rig
// ("alphasense-rectified", ...; rcm.reference_rig).
StereoRig RigFromPython(const pybind11::handle& object);

void BindCameras(pybind11::module_& module);          // cameras.cc
void BindVirtualPinhole(pybind11::module_& module);   // virtual_pinhole.cc
void BindRig(pybind11::module_& module);              // rig.cc
void BindCorrespondences(pybind11::module_& module);  // correspondences.cc
void BindEstimators(pybind11::module_& module);       // estimators.cc
void BindEstimate(pybind11::module_& module);         // estimate.cc
void BindSequence(pybind11::module_& module);         // sequence.cc
void BindBundle(pybind11::module_& module);           // bundle.cc
void BindFrontEnd(pybind11::module_& module);         // frontend.cc
void BindSimulation(pybind11::module_& module);       // simulation.cc
void BindCalibration(pybind11::module_& module);      // calibration.cc

}  // namespace rcm::python

#endif  // RCM_PYTHON_SRC_BINDINGS_H_
