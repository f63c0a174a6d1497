#include "posture_stream.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <future>

namespace fieldpath::app {

PostureStream::PostureStream(std::filesystem::path file, geometry::PathReadOptions options)
    : thread_([this, file = std::move(file), options] { read(file, options); }) {}

PostureStream::~PostureStream() {
  if (thread_.joinable()) thread_.join();
}

void PostureStream::read(const std::filesystem::path& file,
                         const geometry::PathReadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  geometry::PostureChunkSink sink;
  sink.tool_records = [this](const geometry::PathFile& records) {
    std::lock_guard lock(mutex_);
    tool_records_ = records;
  };
  sink.begin = [this](std::size_t n) {
    std::lock_guard lock(mutex_);
    chunks_.resize(n);
    started_ = true;
    changed_.notify_all();
  };
  sink.chunk = [this](std::size_t i, std::span<const geometry::CompactPosture> in) {
    // Converted and bounded on the worker that parsed the chunk (its cache, its core).
    std::vector<zbuffer::Posture> out(in.size());
    TipBounds b{DBL_MAX, DBL_MAX, -DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (std::size_t k = 0; k < in.size(); ++k) {
      const geometry::CompactPosture& p = in[k];
      out[k] = {{p.tip_mm[0], p.tip_mm[1], p.tip_mm[2]},
                {p.axis[0], p.axis[1], p.axis[2]},
                p.spindle_cos,
                p.spindle_sin};
      b.xmin = std::min(b.xmin, double(p.tip_mm[0]));
      b.xmax = std::max(b.xmax, double(p.tip_mm[0]));
      b.ymin = std::min(b.ymin, double(p.tip_mm[1]));
      b.ymax = std::max(b.ymax, double(p.tip_mm[1]));
      b.zmax = std::max(b.zmax, double(p.tip_mm[2]));
    }
    std::lock_guard lock(mutex_);
    chunks_[i].postures = std::move(out);
    chunks_[i].bounds = b;
    chunks_[i].ready = true;
    changed_.notify_all();
  };
  std::exception_ptr error;
  try {
    geometry::scanPathFile(file, options, sink);
  } catch (...) {
    error = std::current_exception();
  }
  std::lock_guard lock(mutex_);
  error_ = error;
  finished_ = true;
  read_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  changed_.notify_all();
}

void PostureStream::waitAll() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return finished_; });
  if (error_) std::rethrow_exception(error_);
}

TipBounds PostureStream::bounds() const {
  std::lock_guard lock(mutex_);
  return bounds_locked();
}

TipBounds PostureStream::bounds_locked() const {
  TipBounds all{DBL_MAX, DBL_MAX, -DBL_MAX, -DBL_MAX, -DBL_MAX};
  for (const Chunk& c : chunks_) {
    if (c.postures.empty()) continue;
    all.xmin = std::min(all.xmin, c.bounds.xmin);
    all.ymin = std::min(all.ymin, c.bounds.ymin);
    all.xmax = std::max(all.xmax, c.bounds.xmax);
    all.ymax = std::max(all.ymax, c.bounds.ymax);
    all.zmax = std::max(all.zmax, c.bounds.zmax);
  }
  return all;
}

TipBounds PostureStream::cutBounds(double length_mm, double top_z) const {
  std::lock_guard lock(mutex_);
  TipBounds all = bounds_locked();
  // (one a core, as TBB's: no more than `--threads`)
  const std::size_t workers = std::max<std::size_t>(
      1, std::min<std::size_t>(
             {std::size_t(std::thread::hardware_concurrency()),
              tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
              chunks_.size()}));
  std::vector<std::future<TipBounds>> parts;
  for (std::size_t w = 0; w < workers; ++w)
    // (each its own copy of the tips' bounds, taken here: `all` is merged into as the first
    // parts return, while a later worker may not have started: a race, ThreadSanitizer's)
    parts.push_back(std::async(std::launch::async, [&, w, b = all]() mutable {
      for (std::size_t c = w; c < chunks_.size(); c += workers)
        for (const zbuffer::Posture& p : chunks_[c].postures) {
          double t = length_mm;  // along the axis, from the tip
          const zbuffer::Vec3f &tip = p.tip_mm, &a = p.axis;
          if (a.z > 0.0f) t = std::min(t, std::max(0.0, (top_z - tip.z) / a.z));
          const double x = tip.x + t * a.x, y = tip.y + t * a.y;
          b.xmin = std::min(b.xmin, x);
          b.xmax = std::max(b.xmax, x);
          b.ymin = std::min(b.ymin, y);
          b.ymax = std::max(b.ymax, y);
        }
      return b;
    }));
  for (auto& part : parts) {
    const TipBounds b = part.get();
    all.xmin = std::min(all.xmin, b.xmin);
    all.xmax = std::max(all.xmax, b.xmax);
    all.ymin = std::min(all.ymin, b.ymin);
    all.ymax = std::max(all.ymax, b.ymax);
  }
  return all;
}

std::size_t PostureStream::postures() const {
  std::lock_guard lock(mutex_);
  std::size_t n = 0;
  for (const Chunk& c : chunks_) n += c.postures.size();
  return n;
}

std::span<const zbuffer::Posture> PostureStream::next() {
  std::unique_lock lock(mutex_);
  if (next_ > 0 && next_ - 1 < chunks_.size())
    std::vector<zbuffer::Posture>().swap(chunks_[next_ - 1].postures);  // cut: no longer read
  for (;;) {
    changed_.wait(lock, [&] {
      return finished_ || (started_ && (next_ >= chunks_.size() || chunks_[next_].ready));
    });
    if (error_) std::rethrow_exception(error_);
    if (next_ >= chunks_.size()) {
      if (started_ || finished_) return {};
      continue;
    }
    if (!chunks_[next_].ready) {
      if (finished_) return {};  // cannot happen without an error
      continue;
    }
    Chunk& c = chunks_[next_++];
    if (!c.postures.empty()) return c.postures;  // (an empty chunk: only comments) → the next
  }
}

}  // namespace fieldpath::app
