#pragma once
/// Reading big path files on all cores: the file mapped into memory, its text cut at line ends
/// into chunks that are parsed in parallel, and the first error in file order reported as a
/// serial reader would report it (the same message, the same line).
#include <cstddef>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/cl_file.h"
#include "path_text.h"  // checkedAxis

namespace fieldpath::geometry::detail {

/// A whole file, read-only, as one piece of text: memory-mapped (read into memory where the file
/// cannot be mapped). Throws common::InputError "FILE: no such file" / "cannot open for reading".
class MappedFile {
 public:
  explicit MappedFile(const std::filesystem::path& file);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view text() const { return text_; }

 private:
  void* map_ = nullptr;
  std::size_t mapped_bytes_ = 0;
  int listed_ = -1;   ///< common::listMappedInput's slot (a SIGBUS names the file)
  std::string copy_;  ///< the contents where mapping failed
  std::string_view text_;
};

/// A piece of a text [begin, end) that starts a line and ends after a '\n' (or at the end).
struct TextChunk {
  std::size_t begin = 0, end = 0;
  std::size_t first_line = 1;  ///< 1-based number of its first line
};

/// Cuts `text` into pieces of about `chunk_bytes` at line ends, numbered in parallel on
/// `threads` workers (0: all cores, as forEachChunk). `continues(line)` (optional) says that a
/// line goes on into the next one (APT's `$`), so that no cut falls inside a record.
std::vector<TextChunk> splitAtLines(std::string_view text, std::size_t chunk_bytes,
                                    unsigned threads,
                                    const std::function<bool(std::string_view)>& continues = {});

/// Calls `work(i)` for i in [0, n) on all cores (TBB; `threads` 0: all of them). When calls
/// throw, the others still finish and the exception of the lowest i is rethrown: the first
/// error in file order when i orders the chunks of a file.
void forEachChunk(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& work);

/// Refuses tool tips beyond any machine: |x|, |y|, |z| > common::kMaxCoordinateMm ("FILE:LINE:
/// ...").
[[noreturn]] void tipTooFar(const Vec3& tip_mm, const std::string& where);
template <class Where>
void checkTip(const Vec3& tip_mm, const Where& where) {
  if (!(tip_mm.cwiseAbs().maxCoeff() <= common::kMaxCoordinateMm)) tipTooFar(tip_mm, where());
}

/// The posture of a record's `count` values, x y z i j k [spindle] (6 or 7, finite), as every
/// reader takes it: its tip checked (checkTip), its axis unit or refused (checkedAxis), both at
/// `where()`.
template <class Where>
Posture checkedPosture(const double* v, std::size_t count, const Where& where) {
  Posture p;
  p.tip_mm = Vec3(v[0], v[1], v[2]);
  checkTip(p.tip_mm, where);
  p.axis = checkedAxis(Vec3(v[3], v[4], v[5]), where);
  p.has_spindle = count == 7;
  p.spindle_rad = p.has_spindle ? v[6] : 0.0;
  return p;
}

/// Where a pass or link block starts: the index of its first posture (which may be the size of
/// the chunk: the block starts in a later chunk) and its kind.
struct BlockMark {
  std::size_t posture = 0;
  PathBlock::Kind kind = PathBlock::Kind::Pass;
};

/// The postures of one chunk of a path file, in file order, with what PathFile keeps of them.
struct PathChunk {
  std::vector<Posture> postures;
  std::vector<std::size_t> lines;    ///< per posture: its line (or row)
  std::vector<std::size_t> limited;  ///< chunk-local indices of `# limit` postures
  std::vector<BlockMark> marks;      ///< `.cl`: markers and blank lines, chunk-local indices
  std::vector<std::size_t> links;    ///< APT: chunk-local indices of the postures after RAPID
  std::vector<std::string> warnings;  ///< safety marks (PathFile::warnings), in order
};

/// Concatenates the chunks (postures, lines, limited, warnings) into `path`, in parallel; blocks
/// are left to the caller.
void concatenate(std::vector<PathChunk>& chunks, unsigned threads, PathFile& path);

/// The safety mark a comment or PPRINT text is (PathFile::warnings: it starts, blanks aside, with
/// "UNSAFE TO RUN" or "UNDER THE REQUIRED CLEARANCE", in any case), or empty.
std::string safetyMark(std::string_view text);

}  // namespace fieldpath::geometry::detail
