"""rcm: the refractive index n of water from stereo images of a camera
calibrated in air (a refractive camera model for underwater stereo).

NumPy in, NumPy out, vectorized; the names mirror the C++ library's in
snake_case (rcm::RefineRefractiveIndex -> rcm.refine_refractive_index).

Conventions (docs/design.md, "Conventions"): camera frame x right, y down,
z forward; the port normal is +z; pixel centers at integer coordinates;
lengths in meters, angles in radians; ``cam1_from_cam0`` maps points in cam0
(the left camera) into cam1 (the right camera). Correspondences are raw
(lens-distorted) pixels [xl, yl, xr, yr].

Errors: every library failure is raised with the library's one-line
message: OSError (FileNotFoundError, PermissionError, ...) for a file that
cannot be read or written, ValueError for bad values, TypeError for a wrong
type or an unknown keyword.

Quick start::

    import rcm
    rig = rcm.read_stereo_rig("rig.yaml")
    matches = rcm.read_correspondences("matches.csv")
    result = rcm.refine_refractive_index(rig, matches)
    print(result.n, result.sigma_n)
"""

from ._version import __version__
from . import _rcm
from ._rcm import (
    FRONT_END_SYSTEMATIC_PX,
    CalibrationTarget,
    Estimate,
    Camera,
    DomeCalibrationResult,
    DomePort,
    DomePortCamera,
    DomePortError,
    ClosedFormResult,
    Correspondences,
    FlatPort,
    FrontEndOptions,
    FrameEstimate,
    MediumSwitch,
    MonoCalibrationResult,
    OnlineEstimate,
    OnlineEstimator,
    OnlineFrameUpdate,
    RefinementOptions,
    RefinementResult,
    RigCamera,
    SequenceBundleAdjustment,
    SequenceBundleOptions,
    SequenceBundleResult,
    SequenceEstimator,
    SequencePair,
    SequenceSimulator,
    SlidingWindowEstimator,
    StereoCalibrationResult,
    StereoFrontEnd,
    StereoMatches,
    StereoRig,
    UnderwaterCalibrationResult,
    VirtualPinholeCamera,
    VirtualPinholeRig,
    WindowEstimate,
    WindowUpdate,
    add_outliers,
    add_pixel_noise,
    calibrate_dome,
    calibrate_dome_from_corners,
    calibrate_mono,
    calibrate_mono_from_corners,
    calibrate_stereo,
    calibrate_stereo_from_corners,
    calibrate_underwater,
    calibrate_underwater_from_corners,
    closed_form_n,
    central_dome_error,
    compare_trajectories,
    closed_form_refractive_index,
    default_refinement_options,
    estimate_refractive_index,
    evaluate_dome_port_error,
    ignored_dome_error,
    match_stereo,
    medium_prior,
    read_calibration_target,
    read_correspondences,
    read_stereo_rig,
    reference_rig,
    refine_refractive_index,
    render_target,
    sample_correspondences,
    simulate,
    virtual_pinhole_maps,
    water_refractive_index,
    write_correspondences,
    write_stereo_rig,
)


def remap(image, maps, interpolation=None):
    """cv2.remap of a raw image through (map_x, map_y) of
    VirtualPinholeCamera.maps, bilinear by default, black outside."""
    import cv2

    map_x, map_y = maps
    if interpolation is None:
        interpolation = cv2.INTER_LINEAR
    return cv2.remap(image, map_x, map_y, interpolation,
                     borderMode=cv2.BORDER_CONSTANT, borderValue=0)


__all__ = [name for name in dir(_rcm) if not name.startswith("_")] + [
    "remap", "__version__"]
