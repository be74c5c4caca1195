#!/usr/bin/env bash
# Which tests run in which pass of scripts/test.sh (sourced by it and by
# scripts/test_sanitizers.sh). Every test runs in at least one pass, and a
# slow one in one pass only, unless its work differs between them:
#
#   release_only  the Release pass only (build/): statistics, accuracies on
#                 rendered images, byte-for-byte equalities, whose code
#                 other tests run under the sanitizers too (in brackets);
#   budgeted      both passes: the tests of files that use
#                 tests/support/test_budget.h, which under the sanitizers
#                 do a few trials or views and check no statistic, so that
#                 their statistics are checked in Release;
#   the rest      the sanitizer pass only (build-sanitize/, AddressSanitizer
#                 and UndefinedBehaviorSanitizer): the same code, the same
#                 checks, and memory errors and undefined behaviour caught
#                 as well. The Release build compiles them (gcc), and the
#                 installed package's checks (scripts/test_install.sh) and
#                 the node's test run on it.
#
# gtest filter patterns (a whole test name, or a prefix and *), one per
# entry; check_test_passes requires each to match at least one test, and
# every test of a file that includes test_budget.h to be in one of the two
# lists.

# [In brackets, the sanitized tests that run the same code.]
release_only=(
  # [RectifiedRigN1333, UnrectifiedRigN1345]: the same pipeline at other n
  'StereoFrontEndAcceptance.RectifiedRigN1345'
  'StereoFrontEndAcceptance.UnrectifiedRigN1333'
  # [VirtualPinholeRig.*, UndistortCli.*]: corrected images, 3 rigs x 20 frames
  'VirtualPinholeRig.CorrectedImagesSatisfyPinholeEpipolarGeometry'
  # [ThickPortRefinement exact tests, EstimateCli.SimulatedThickPort...]
  'ThickPortRefinement.WithinOneAndAHalfCramerRaoBoundsWhereThinPortIsBiased'
  'ThickPortRefinement.MonteCarloJointAirGapSigmaIsHonest'
  # [StereoCalibration.*, UnderwaterCalibration.*, CrossValidation.*]: Monte Carlo
  'StereoCalibration.MonteCarloSigmaIsHonest'
  'UnderwaterCalibration.MonteCarloSigmaIsHonest'
  'JointAirWaterCalibration.MonteCarloSigmaIsHonest'
  'OpenCvSampleStereo.LeaveOneOutIsStable'
  # [BoardWarp.Exact*, MeanFramesProjection.JacobianMatchesCentralDifferences]:
  # Monte Carlo of the warp's sigma and of the mean-frames projection spread
  'BoardWarp.MonteCarloWarpSigmaIsHonest'
  'MeanFramesProjection.MonteCarloSpreadIsThePredictedOne'
  # [CalibrationPropagation.MonteCarloRefine*, .MonteCarloFreeRotation*,
  # OnlineEstimator.*, SlidingWindowEstimator.*]: the drift Monte Carlo of
  # the online and window estimators (32 s of the Release pass's CPU)
  'CalibrationPropagation.MonteCarloOnlineSigma*'
  'CalibrationPropagation.MonteCarloWindowSigma*'
  # [BoardWarp.Exact*, BoardRendering.*]: the bow and focal lengths on renders
  'BoardWarpOnRenders.BowRecoveredAndFocalLengthsUnbiased'
  # [BoardRendering.PixelsAreTheExactPixelIntegral, CalibrateCli.*, UnderwaterCli.*]:
  # the accuracy of a calibration, and of the detected corners, on renders
  'CalibrationOnRenders.ChessboardEquidistantDatasetRig'
  'CalibrationOnRenders.ChessboardEucmRecoversTheTruth'
  'BoardRendering.NarrowRigCornersAreDetectedWhereTheyProject'
  'BoardRendering.AlphasenseCornersAreDetectedWhereTheyProject'
  'BoardRendering.BorderCornersAreNotPulledOutward'
  # [DomeCalibrationOnRenders.FourViewsRunEndToEnd, TargetRenderer.Dome*,
  # DomeCalibration.*]: the rendered dome dives' decentering (8-15 s each)
  'DomeCalibrationOnRenders.OneCameraDive'
  'DomeCalibrationOnRenders.StereoDive'
  # [OpenCvSampleStereo.EveryPairIsDetectedConsistently]: the RMS against OpenCV's
  'OpenCvSampleStereo.RmsNoWorseThanStereoCalibrate'
  'OpenCvSampleStereo.RationalRmsAtOrBelowRadTan'
  # [StereoFrontEnd.*, FeatureDetector.*]: n within 2e-3 with SIFT and AKAZE
  'StereoFrontEnd.SiftGivesTheIndexWithin2e3'
  'StereoFrontEnd.AkazeGivesTheIndexWithin2e3'
  # [SequenceSimulator.*, StereoRenderer.*, SimulateCli.*]: determinism
  'SequenceSimulator.SameSeedSameFrames'
  'SequenceSimulator.SameSeedSameFramesWithABoard'
  'StereoRenderer.SameInputsGiveTheSameBytes'
  'SimulateCli.SameSeedSameBytes'
  # [ThinPortBias.*]: the table of docs/thin_port_bias.md, recomputed
  'ThinPortBias.DocsTableIsCurrent'
  # [UnderwaterCli.OneCameraGivesN, .TooFewViews, .NPinnedAtTheUpperBound,
  # UnderwaterCalibration.*, EstimateCli.*]: the two dives' accuracy end to end
  'UnderwaterCli.DatasetRigThatDriftedHalfADegree'
  'UnderwaterCli.NarrowRigThatDriftedHalfADegree'
  # [JointAirWaterCalibration.Exact*, UnderwaterCli.JointAirAndWaterBadInput]:
  # the joint calibration of air and water end to end
  'UnderwaterCli.JointAirAndWater'
  # [OpenCvSampleStereo.*, CalibrateCli.Corners*]: rcm against mrcal on the
  # sample pairs, a comparison of two solvers' numbers
  'MrcalPeer.*'
  # [EstimateImagesCli.FoldersGiveNAndThePictures, ...]: each estimator on images
  'EstimateImagesCli.EveryEstimatorRunsOnImages'
  # [UnderwaterCalibration.NAtABoundIsAnError, UnderwaterCli.TooFewViews]: the
  # bound's refusal end to end
  'UnderwaterCli.NPinnedAtTheUpperBound'
  # [UnderwaterModelSelection.Exact*]: the selection's Monte Carlo
  'UnderwaterModelSelection.MonteCarloHonestUnderEachModelError'
  # [StereoCalibration.DoubleSpherePinnedAtItsBoundIsAnError]: double sphere's
  # focal length sigma on noisy corners
  'StereoCalibration.NoisyDoubleSphereReportsItsFocalLengthUncertain'
  # [CalibrateCli.FoldersToCamchainAndReport, UnderwaterCli.*]: --json and
  # --out together
  'CalibrateCli.JsonOnStdoutAndAnOutputFolder'
  # [CrossValidation.NeedsTwoFolds, CalibrateCli.*]: the folds' table
  'CrossValidation.FlatBoardHasNoBowlRow'
  # The heaviest end-to-end runs under the sanitizers (15-19 s each there,
  # a third of that in Release), each beside a cheaper test of the same
  # code that the sanitizer pass keeps:
  # [UnderwaterCalibration.ExactSingleCamera, UnderwaterCli.TooFewViews]:
  # one camera under water end to end
  'UnderwaterCli.OneCameraGivesN'
  # [LivePipeline.HoldKeepsTheMapsAndResetMovesThem, .RefusesBadPairs...]:
  # the live pipeline through air, water and air
  'LivePipeline.FollowsAirWaterAirAndItsMapsFollowN'
  # [StereoFrontEndAcceptance.UnrectifiedRigN1345]: the same front end on
  # the rectified rig
  'StereoFrontEndAcceptance.RectifiedRigN1333'
  # [BagStereoSource.*, CalibrateCli.FoldersToCamchainAndReport, the bad-input
  # table's CalibrateCornersAndABag]: calibration from a bag
  'CalibrateCli.BagGivesTheFoldersResult'
  # [UnderwaterModelSelection.ExactAirGapChoosesAGap]: the selection on
  # exact corners, with the bow
  'UnderwaterModelSelection.ExactBowedBoardChoosesTheBow'
  # [LivePipeline.*, EstimateImagesCli.*, DemoCli.*, SequenceEstimator.
  # RefusesBadPairsAndOptions]: the sequence engine on rendered pairs (the
  # sanitized tests run it through the live pipeline, rcm estimate and the
  # demo)
  'SequenceEstimator.TheLivePipelineRunsIt'
  'SequenceEstimator.FollowsATurnedCam1AndSaysTheCalibrationIsStale'
  'SequenceEstimator.EstimatesOverTheCurrentMedium'
  # The heaviest CLI runs under the sanitizers (13-32 s each there, measured
  # on build-sanitize/ of 319e96a), each beside a sanitized test of the
  # same code:
  # [CalibrateCli.FoldersToCamchainAndReport]: corners out and back in, a
  # byte-for-byte equality; mrcal-style names; a board in one image only
  'CalibrateCli.CornersOutThenCornersGivesTheSameCamchain'
  'CalibrateCli.CornersOfMrcalStyleNamesPairByTheirNumber'
  'CalibrateCli.BoardInOneImageOnlyIsNamedAndUsedForThatCamera'
  # [the bad-input table's calibrate rows, CalibrateCli.FoldersToCamchain...]:
  # detection over every image that finds nothing, an unreadable image
  'CalibrateCli.NoTargetAnywhere'
  'CalibrateCli.UnreadableImageSkipsItsPairOnly'
  # [EstimateImagesCli.FoldersGiveNAndThePictures, SimulateCli.*,
  # LivePipeline.*, DemoCli.UnwritableFolderIsOneLineError]: the demo's
  # renders, pair loop and pictures
  'DemoCli.EstimatesNFromTheImagesAndWritesThePictures'
  # [BagStereoSource.*, EstimateImagesCli.FoldersGiveNAndThePictures,
  # EstimateImagesCli.BagWithoutTheTopicsIsOneLine]: a bag against folders
  'EstimateImagesCli.BagGivesTheSameNAsTheFolders'
  # [SequenceEstimator.BundleFallsBackToRefineForAStillRig, StereoTracker.Bad*,
  # SequenceBundleAdjustment.*]: the bundle's accuracy on rendered dives
  'StereoTracker.RenderedDiveGivesTheBundleNTurnAndTrajectory'
  'SequenceEstimator.BundleOverTheRenderedPairs'
  # [OdometryStudy.BadOptionsRefusedInOneLine, TrajectoryError.*,
  # SequenceBundleAdjustment.*]: the odometry table's models on renders
  'OdometryStudy.ModelsRankAsThePaperSays'
  # [EstimateImagesCli.EveryEstimatorRunsOnImages, SequenceEstimator.Bundle*]:
  # rcm estimate --estimator bundle --out on renders, end to end
  'EstimateImagesCli.BundleWritesTheTrajectory'
  # [MonoCalibration.*, CalibrateMonoCli.CornersFileOfOneCamera...]: one
  # camera's Monte Carlo, and against cv::calibrateCamera on real images
  'MonoCalibration.MonteCarloSigmaIsHonest'
  'MonoCalibrationOpenCvSample.LeftImagesEqualCalibrateCamera'
  'CalibrateMonoCli.OpenCvSampleLeftImagesEqualCalibrateCamera'
  # [DomeCalibration.MonteCarlo*, ...NWithTheDecentering]: the dome
  # calibration's Monte Carlos and its exact test with n (1.4 s in Release;
  # rcm calibrate --port dome --estimate-n runs under the sanitizers)
  'DomeCalibration.MonteCarlo*'
  'DomeCalibration.NoiseFreeRecoversNWithTheDecentering'
)

budgeted=(
  # The dome calibration's fast tests (its Monte Carlos and the slowest
  # exact test run in the Release pass only: the CLI tests take the same
  # paths under the sanitizers)
  'DomeCalibration.*'
  'UnderwaterCli.*'
  'UnderwaterModelSelection.*'
  'UnderwaterCalibration.LensCovarianceReachesN'
  'UnderwaterCalibration.LensCorrelationKeepsTargetFreeSigmaHonest'
  'UnderwaterCalibration.PortsInTheSidecarKeepTargetFreeSigmaHonest'
  'CalibrationPropagation.*'
  'MediumDrift.*'
  'MediumPrior.*'
  # (fast tests in those files)
  'WaterRefractiveIndex.*'
  'UnderwaterCandidates.*'
  'UnderwaterModelSelectionOptions.*'
  'SequenceBundleAdjustment.*'
  'EstimateRefractiveIndexFromTracks.*'
  'SequenceBundleOptions.*'
  'BundleMotion.*'
)

# ':'-joined patterns, for GTEST_FILTER.
join_patterns() { local IFS=':'; echo "$*"; }

# Every test name of BUILD_DIR's test suites (bin/*_tests), one per line.
list_tests() {
  local build=$1 suites suite
  suites=$(find "$build/bin" -maxdepth 1 -name '*_tests' -type f | sort)
  [[ -n $suites ]] || { echo "test_passes: no test suites in $build/bin" >&2; return 1; }
  for suite in $suites; do
    "$suite" --gtest_list_tests | awk '/^[^ ]/ {s = $1} /^  / {print s $1}'
  done
}

# Whether NAME matches one of the patterns after it.
matches_any() {
  local name=$1 pattern
  shift
  for pattern in "$@"; do
    # shellcheck disable=SC2053  # the pattern is a glob on purpose
    [[ $name == $pattern ]] && return 0
  done
  return 1
}

# Checks the lists against TESTS (list_tests' output; run from the
# repository root).
check_test_passes() {
  local tests=$1 pattern found name file
  for pattern in "${release_only[@]}" "${budgeted[@]}"; do
    found=0
    while read -r name; do
      # shellcheck disable=SC2053
      [[ $name == $pattern ]] && { found=1; break; }
    done <<<"$tests"
    ((found)) || { echo "test_passes: pattern '$pattern' matches no test" >&2; return 1; }
  done
  while read -r file; do
    while read -r name; do
      matches_any "$name" "${release_only[@]}" "${budgeted[@]}" || {
        echo "test_passes: $name ($file uses test_budget.h) is in neither release_only nor budgeted" >&2
        return 1
      }
    done < <(sed -n 's/^TEST\(_F\|_P\)\?(\([A-Za-z0-9_]*\), *\([A-Za-z0-9_]*\)).*/\2.\3/p' "$file")
  done < <(grep -rl --include='*_test.cc' 'support/test_budget.h' tests)
}
