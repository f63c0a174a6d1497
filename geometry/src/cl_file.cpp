#include "fieldpath/geometry/cl_file.h"

#include <stdexcept>

#include "fieldpath/common/errors.h"

namespace fieldpath::geometry {

std::vector<Posture> readClFile(const std::filesystem::path& file) {
  throw common::InputError(file.string() + ": .cl reading is not implemented yet");
}
void writeClFile(const std::filesystem::path&, std::span<const Posture>, std::string_view) {
  throw std::logic_error("writeClFile: not implemented yet");
}
void writeAptFile(const std::filesystem::path&, std::span<const Posture>, const AptHeader&) {
  throw std::logic_error("writeAptFile: not implemented yet");
}
std::vector<Posture> readAptFile(const std::filesystem::path& file) {
  throw common::InputError(file.string() + ": APT reading is not implemented yet");
}

}  // namespace fieldpath::geometry
