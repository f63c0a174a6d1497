#include "path_chunks.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/input_file.h"
#include "path_text.h"

namespace fieldpath::geometry::detail {

MappedFile::MappedFile(const std::filesystem::path& file) {
  requireRegularFile(file);
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw common::InputError(file.string() + ": cannot open for reading");
  struct stat st {};
  if (::fstat(fd, &st) == 0 && st.st_size > 0) {
    void* map =
        ::mmap(nullptr, static_cast<std::size_t>(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
    if (map != MAP_FAILED) {
      map_ = map;
      mapped_bytes_ = static_cast<std::size_t>(st.st_size);
      listed_ = common::listMappedInput(file.string(), map_, mapped_bytes_);
      // Read ahead: the chunks are parsed in parallel from the first to the last.
      ::madvise(map_, mapped_bytes_, MADV_SEQUENTIAL | MADV_WILLNEED);
      text_ = std::string_view(static_cast<const char*>(map_), mapped_bytes_);
    }
  }
  ::close(fd);
  if (!map_) {  // empty, or a file system that cannot map: read it
    std::ifstream in(file, std::ios::binary);
    if (!in) throw common::InputError(file.string() + ": cannot open for reading");
    copy_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) throw common::InputError(file.string() + ": read error");
    text_ = copy_;
  }
}

MappedFile::~MappedFile() {
  common::unlistMappedInput(listed_);
  if (map_) ::munmap(map_, mapped_bytes_);
}

void forEachChunk(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& work) {
  std::vector<std::exception_ptr> errors(n);
  const auto body = [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      try {
        work(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  if (threads == 1 || n <= 1) {
    body(tbb::blocked_range<std::size_t>(0, n));
  } else {
    tbb::task_arena arena(threads == 0 ? tbb::task_arena::automatic : int(threads));
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), body); });
  }
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

std::vector<TextChunk> splitAtLines(std::string_view text, std::size_t chunk_bytes,
                                    unsigned threads,
                                    const std::function<bool(std::string_view)>& continues) {
  chunk_bytes = std::max<std::size_t>(chunk_bytes, 1);
  std::vector<TextChunk> chunks;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = std::min(text.size(), begin + chunk_bytes);
    for (;;) {
      // the cut goes after the next '\n' at or beyond `end - 1`
      const std::size_t nl = end == 0 ? std::string_view::npos : text.find('\n', end - 1);
      if (nl == std::string_view::npos) {
        end = text.size();
        break;
      }
      end = nl + 1;
      if (!continues || end >= text.size()) break;
      const std::size_t line_start = text.rfind('\n', nl == 0 ? 0 : nl - 1);
      const std::size_t from = line_start == std::string_view::npos || nl == 0 ? 0 : line_start + 1;
      if (!continues(text.substr(from, nl - from))) break;
      ++end;  // the record goes on: look for the next line end
    }
    chunks.push_back({begin, end, 0});
    begin = end;
  }
  // Line numbers: the '\n's before each chunk, counted in parallel.
  std::vector<std::size_t> newlines(chunks.size());
  forEachChunk(chunks.size(), threads, [&](std::size_t i) {
    const char* p = text.data() + chunks[i].begin;
    newlines[i] = static_cast<std::size_t>(std::count(p, text.data() + chunks[i].end, '\n'));
  });
  std::size_t line = 1;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    chunks[i].first_line = line;
    line += newlines[i];
  }
  return chunks;
}

void tipTooFar(const Vec3& tip_mm, const std::string& where) {
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(tip_mm[k]) <= common::kMaxCoordinateMm)) {
      std::ostringstream why;
      why << "tool tip "
          << "xyz"[k] << " = " << tip_mm[k] << " mm is beyond +-" << common::kMaxCoordinateMm
          << " mm (no machine is that large)";
      failAt(where, why.str());
    }
  }
  failAt(where, "tool tip out of range");
}

void concatenate(std::vector<PathChunk>& chunks, unsigned threads, PathFile& path) {
  std::vector<std::size_t> offset(chunks.size() + 1, 0);
  for (std::size_t i = 0; i < chunks.size(); ++i)
    offset[i + 1] = offset[i] + chunks[i].postures.size();
  path.postures.resize(offset.back());
  path.lines.resize(offset.back());
  forEachChunk(chunks.size(), threads, [&](std::size_t i) {
    std::copy(chunks[i].postures.begin(), chunks[i].postures.end(),
              path.postures.begin() + std::ptrdiff_t(offset[i]));
    std::copy(chunks[i].lines.begin(), chunks[i].lines.end(),
              path.lines.begin() + std::ptrdiff_t(offset[i]));
    std::vector<Posture>().swap(chunks[i].postures);  // free as we go
    std::vector<std::size_t>().swap(chunks[i].lines);
  });
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    for (std::size_t k : chunks[i].limited) path.limited.push_back(offset[i] + k);
    for (std::string& w : chunks[i].warnings) path.warnings.push_back(std::move(w));
  }
}

std::string safetyMark(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t' || text.back() == '\r'))
    text.remove_suffix(1);
  auto startsWith = [&](std::string_view word) {
    if (text.size() < word.size()) return false;
    for (std::size_t i = 0; i < word.size(); ++i)
      if (std::toupper(static_cast<unsigned char>(text[i])) != word[i]) return false;
    return true;
  };
  return startsWith("UNSAFE TO RUN") || startsWith("UNDER THE REQUIRED CLEARANCE")
             ? std::string(text)
             : std::string();
}

}  // namespace fieldpath::geometry::detail
