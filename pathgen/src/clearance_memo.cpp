#include "clearance_memo.h"

#include <memory>

namespace fieldpath::pathgen {

ClearanceMemo::ClearanceMemo() : impl_(std::make_unique<Impl>()) {}
ClearanceMemo::~ClearanceMemo() = default;
std::size_t ClearanceMemo::reused() const { return impl_->reused; }

void ClearanceMemo::forgetUnused() {
  const std::uint32_t now = impl_->generation;
  std::erase_if(impl_->postures, [now](const auto& entry) { return entry.second.used != now; });
  std::erase_if(impl_->motions, [now](const auto& entry) { return entry.second.used != now; });
  ++impl_->generation;
}

void ClearanceMemo::clear() {
  impl_->postures.clear();
  impl_->motions.clear();
}

}  // namespace fieldpath::pathgen
