#include "clearance_memo.h"

#include <memory>

namespace fieldpath::pathgen {

ClearanceMemo::ClearanceMemo() : impl_(std::make_unique<Impl>()) {}
ClearanceMemo::~ClearanceMemo() = default;
std::size_t ClearanceMemo::reused() const { return impl_->reused; }

}  // namespace fieldpath::pathgen
