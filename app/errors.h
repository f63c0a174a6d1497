#pragma once
/// Exit codes: bad input (common::InputError, one clear line naming the file, line or key) → 1;
/// anything else → 2 (internal failure).
#include "fieldpath/common/errors.h"

namespace fieldpath::app {
using common::InputError;
}  // namespace fieldpath::app
