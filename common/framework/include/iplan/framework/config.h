// The services' strict configuration reader is iplan::core::ConfigSection
// (iplan/core/config.h), the one reader under every parameter file; parameter
// structs declare their keys once with Serialize (iplan/core/params.h). The
// names stay available here for the services.
#pragma once

#include "iplan/core/config.h"

namespace iplan::framework {

using core::Check;
using core::ConfigError;
using core::ConfigSection;
using core::InRange;
using core::NonNegative;
using core::OneOf;
using core::Positive;

}  // namespace iplan::framework
