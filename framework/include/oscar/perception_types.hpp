#pragma once
/// @file The perception cue types (idl/oscar/perception.idl): camera images, tag detections and
/// the fused landmark pose (issue 7, seed 004 §4.2).

#include <oscar/perception.h>
#include <oscar/perceptionPubSubTypes.h>

#include "oscar/cue.hpp"

OSCAR_DECLARE_CUE_TYPE(oscar, CameraImage)
OSCAR_DECLARE_CUE_TYPE(oscar, TagDetections)
OSCAR_DECLARE_CUE_TYPE(oscar, LandmarkPose)
