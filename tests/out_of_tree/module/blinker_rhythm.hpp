#pragma once
// The blinker's own cue type (blinker_types.idl), for its kernel and its tests.
#include <blinker/blinker_types.h>
#include <blinker/blinker_typesPubSubTypes.h>
#include <oscar/cue.hpp>

OSCAR_DECLARE_CUE_TYPE(blinker, Rhythm)
