#pragma once
/// A path file read on all cores beside the simulation (issue 13): the reading runs on a thread of
/// its own and hands chunks of Z-buffer postures out in file order, each as soon as it and every
/// chunk before it are parsed, so that the engine cuts chunk k while chunk k+1 is parsed.
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

/// Tips' extent (mm), as the postures were rounded to float.
struct TipBounds {
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0, zmax = 0;
};

class PostureStream {
 public:
  /// Starts reading `file` (any path format).
  PostureStream(std::filesystem::path file, geometry::PathReadOptions options);
  /// Waits for the reading thread (it finishes its chunks).
  ~PostureStream();
  PostureStream(const PostureStream&) = delete;
  PostureStream& operator=(const PostureStream&) = delete;

  /// Waits until the whole file is read; rethrows its first error (common::InputError).
  void waitAll();
  /// After waitAll: every tip's extent and the number of postures.
  TipBounds bounds() const;
  std::size_t postures() const;
  /// After waitAll: the XY extent of what the tool can cut (bounds' zmax: the highest tip): the
  /// tips, and each posture's axis from its tip up to where it leaves the stock's top `top_z`
  /// (at most `length_mm` along it: a tilted shank cuts beside the tip), on all cores.
  TipBounds cutBounds(double length_mm, double top_z) const;
  /// After waitAll: an APT file's tool records (file, cutters, tool_loads; app/cutter_note.h),
  /// none for other formats.
  const geometry::PathFile& toolRecords() const { return tool_records_; }
  /// Seconds from the start to the last chunk parsed (after waitAll).
  double readSeconds() const { return read_seconds_; }

  /// The next chunk in file order (waits for it), an empty span after the last; the previous
  /// chunk is released. Rethrows the reading's error when it reaches it.
  std::span<const zbuffer::Posture> next();

 private:
  struct Chunk {
    bool ready = false;
    std::vector<zbuffer::Posture> postures;
    TipBounds bounds;
  };
  void read(const std::filesystem::path& file, const geometry::PathReadOptions& options);
  TipBounds bounds_locked() const;  ///< bounds(), mutex_ held

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool started_ = false;   ///< the chunk count is known
  bool finished_ = false;  ///< the reading thread is done (or failed)
  std::exception_ptr error_;
  std::vector<Chunk> chunks_;
  std::size_t next_ = 0;  ///< next chunk handed out
  double read_seconds_ = 0;
  geometry::PathFile tool_records_;  ///< set by the reading thread before its first chunk
  std::thread thread_;
};

}  // namespace fieldpath::app
