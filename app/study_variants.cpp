/// The study's variants and options (study.h, study_text.h): a variant's name, the parsers of
/// `study`'s lists, the names and numbers its text writes, the machine it ran on.
#include "study.h"
#include "study_text.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <utility>

#include "fieldpath/common/errors.h"

namespace fieldpath::app {
using namespace study_detail;
using common::InputError;

std::string StudyVariant::name() const {
  std::string base = nameWithoutBackend();
  if (isVoxel() && named_backend)
    base += std::string(" [") + backendName(voxel.backend) + " build]";
  return base;
}

std::string StudyVariant::nameWithoutBackend() const {
  const char* label = pathgen::fieldModeNames(mode).label;
  if (!isVoxel()) return label;
  std::ostringstream s;
  s << label << ' ' << voxel.voxel_size_mm << " mm " << interpolationName(voxel.interpolation)
    << ' ' << storedName(voxel.stored);
  if (voxel.refine_tolerance > 0.0)
    s << " refined " << 100 * voxel.refine_tolerance << " % to "
      << voxel.voxel_size_mm / double(1 << voxel.refine_levels) << " mm"
      << (voxel.refine_region == field::RefineRegion::Path ? " near its path" : " everywhere");
  return s.str();
}

namespace {
/// "a,b,c" → finite numbers accepted by `ok`; InputError naming `key` and `what` otherwise
/// (an empty list or a trailing comma included).
template <class Ok>
std::vector<double> parseNumbers(const std::string& text, const std::string& key, Ok&& ok,
                                 const std::string& what) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    // Blanks around an item are read past (" 2" was taken, "2 " refused); hexadecimal is no
    // millimetre (strtod read `0x10` as 16: a study sweep's).
    const std::size_t first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v) || !ok(v) ||
        item.find_first_of("xX") != std::string::npos)
      throw InputError(key + ": '" + item + "' is not " + what);
    values.push_back(v);
  }
  if (values.empty() || text.back() == ',')
    throw InputError(key + ": give " + what + ", separated by commas");
  return values;
}
}  // namespace

std::vector<double> parseVoxelSizes(const std::string& text, const std::string& key) {
  return parseNumbers(
      text, key, [](double h) { return h > 0.0; }, "voxel sizes > 0 mm (e.g. 2,1,0.5)");
}

std::vector<double> parseRefineTolerances(const std::string& text, std::size_t sizes,
                                          const std::string& key) {
  std::vector<double> tolerances = parseNumbers(
      text, key, [](double pct) { return pct >= 0.0; }, "tolerances >= 0 % (e.g. 7.5,2.5,0.5)");
  if (tolerances.size() != sizes)
    throw InputError(key + ": give one tolerance (%) per voxel size (" + std::to_string(sizes) +
                     ")");
  for (double& t : tolerances) t /= 100.0;
  return tolerances;
}

namespace {
/// "a,b" → the values of the two names `first` and `second`; InputError naming `key` otherwise.
template <class T>
std::vector<T> parsePair(const std::string& text, const std::string& key,
                         std::pair<const char*, T> first, std::pair<const char*, T> second) {
  const std::string names = std::string(first.first) + " or " + second.first;
  std::vector<T> result;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == first.first)
      result.push_back(first.second);
    else if (item == second.first)
      result.push_back(second.second);
    else
      throw InputError(key + ": '" + item + "' is not " + names);
  }
  if (result.empty() || text.back() == ',') throw InputError(key + ": give " + names + " or both");
  return result;
}
}  // namespace

std::vector<field::StoredQuantity> parseStored(const std::string& text, const std::string& key) {
  return parsePair(text, key, std::pair{"force", field::StoredQuantity::Force},
                   std::pair{"plane_ratio", field::StoredQuantity::PlaneRatio});
}

const char* backendName(field::FieldBackend backend) {
  switch (backend) {
    case field::FieldBackend::Cpu:
      return "cpu";
    case field::FieldBackend::Cuda:
      return "cuda";
    case field::FieldBackend::Reference:
      return "reference";
    default:
      return "auto";
  }
}

std::vector<field::FieldBackend> parseBackends(const std::string& text, const std::string& key) {
  std::vector<field::FieldBackend> result;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::optional<field::FieldBackend> backend = field::fieldBackendNamed(item);
    if (!backend) throw InputError(key + ": '" + item + "' is not auto, cpu, cuda or reference");
    if (std::find(result.begin(), result.end(), *backend) != result.end())
      throw InputError(key + ": '" + item + "' twice");
    result.push_back(*backend);
  }
  if (result.empty() || text.back() == ',')
    throw InputError(key + ": give builds among auto, cpu, cuda, reference (e.g. reference,cpu)");
  return result;
}

std::vector<field::RefineRegion> parseRefineRegions(const std::string& text,
                                                    const std::string& key) {
  return parsePair(text, key, std::pair{"path", field::RefineRegion::Path},
                   std::pair{"reach", field::RefineRegion::Reach});
}

std::vector<field::Interpolation> parseInterpolations(const std::string& text,
                                                      const std::string& key) {
  return parsePair(text, key, std::pair{"trilinear", field::Interpolation::Trilinear},
                   std::pair{"quadratic", field::Interpolation::Quadratic});
}

namespace study_detail {

std::string interpolationName(field::Interpolation interpolation) {
  return interpolation == field::Interpolation::Quadratic ? "quadratic" : "trilinear";
}

std::string storedName(field::StoredQuantity stored) {
  return stored == field::StoredQuantity::PlaneRatio ? "plane_ratio" : "force";
}

std::string number(double value, int precision) {
  // Empty for inf / nan, as common/csv.h's cells: the CSVs are its main reader (a `nan` cell,
  // e.g. the brute-force speed-up under --no-brute-force, breaks some CSV readers).
  if (!std::isfinite(value)) return "";
  std::ostringstream s;
  s << std::setprecision(precision) << value;
  return s.str();
}

std::string machineDescription() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  int cores = 0;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0 && model == "unknown CPU") {
      const auto colon = line.find(':');
      if (colon != std::string::npos) model = line.substr(colon + 2);
    }
    if (line.rfind("processor", 0) == 0) ++cores;
  }
  std::string load;
  std::ifstream loadavg("/proc/loadavg");
  std::string one, five, fifteen;
  if (loadavg >> one >> five >> fifteen)
    load = ", load average at the end " + one + " " + five + " " + fifteen;
  return model + ", " + std::to_string(cores) + " logical cores" + load;
}

}  // namespace study_detail

}  // namespace fieldpath::app
