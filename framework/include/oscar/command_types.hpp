#pragma once
/// @file The request types of OSCAR's own command ports (idl/oscar/commands.idl).

#include <oscar/commands.h>
#include <oscar/commandsPubSubTypes.h>

#include "oscar/idl_type_info.hpp"

OSCAR_DECLARE_IDL_TYPE(oscar, SetFrameMode)
