/// The CUDA node build (node_cuda.h): one thread per masked node of a leaf, a block of 512
/// threads per leaf; each thread sums the samples of the cell list around its node (and around
/// the points its surface rule lifts it to) with node_kernel.h's math, the CPU's.
#include <cuda_runtime.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "fieldpath/common/cuda_check.h"
#include "node_cuda.h"

namespace fieldpath::field::kernel {
namespace {

/// Device memory freed on scope exit.
template <class T>
struct DeviceArray {
  T* ptr = nullptr;
  explicit DeviceArray(std::size_t n) {
    if (n) FIELDPATH_CUDA_CHECK(cudaMalloc(&ptr, n * sizeof(T)));
  }
  DeviceArray(const T* host, std::size_t n, cudaStream_t stream) : DeviceArray(n) {
    if (n)
      FIELDPATH_CUDA_CHECK(
          cudaMemcpyAsync(ptr, host, n * sizeof(T), cudaMemcpyHostToDevice, stream));
  }
  ~DeviceArray() {
    if (ptr) FIELDPATH_CUDA_WARN(cudaFree(ptr));
  }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;
};

__global__ void nodeKernel(CellTable table, NodeJob job, const LeafTask* leaves,
                           const unsigned long long* first, NodeValue* out) {
  const LeafTask& leaf = leaves[blockIdx.x];
  const int offset = threadIdx.x;  // (i·8 + j)·8 + k
  const std::uint64_t word = leaf.mask[offset >> 6];
  if (!((word >> (offset & 63)) & 1u)) return;
  // The node's rank among the leaf's masked nodes.
  unsigned long long rank = first[blockIdx.x];
  for (int w = 0; w < (offset >> 6); ++w) rank += __popcll(leaf.mask[w]);
  rank += __popcll(word & ((std::uint64_t{1} << (offset & 63)) - 1));
  const int i = offset >> 6, j = (offset >> 3) & 7, k = offset & 7;
  const double h = job.h_mm;
  const D3 x{(leaf.origin[0] + i) * h, (leaf.origin[1] + j) * h, (leaf.origin[2] + k) * h};
  CellHood hood{&table, &job.law};
  out[rank] = nodeValue(hood, job.law, job.rules, x);
}

}  // namespace

bool cudaNodeBuildAvailable() {
  // The first call also makes the device's context (cudaFree(0)): CUDA's start-up, once per
  // process, here rather than inside the first build that asks for the device.
  static const bool available = [] {
    int count = 0;
    return cudaGetDeviceCount(&count) == cudaSuccess && count > 0 &&
           cudaFree(nullptr) == cudaSuccess;
  }();
  return available;
}

struct CudaNodeBuild::State {
  struct Stream {
    cudaStream_t s = nullptr;
    Stream() { FIELDPATH_CUDA_CHECK(cudaStreamCreate(&s)); }
    ~Stream() {
      if (s) FIELDPATH_CUDA_WARN(cudaStreamDestroy(s));
    }
  } stream;
  std::vector<unsigned long long> first;
  std::size_t nodes = 0;
  // The device's copies (freed on scope exit; the stream is synchronised first, ~CudaNodeBuild).
  std::unique_ptr<DeviceArray<double>> x, y, z, nx, ny, nz, w;
  std::unique_ptr<DeviceArray<std::int32_t>> id, starts;
  std::unique_ptr<DeviceArray<std::uint8_t>> far_face;
  std::unique_ptr<DeviceArray<LeafTask>> tasks;
  std::unique_ptr<DeviceArray<unsigned long long>> firsts;
  std::unique_ptr<DeviceArray<NodeValue>> out;
};

CudaNodeBuild::CudaNodeBuild(const CellTable& table, const NodeJob& job,
                             const std::vector<LeafTask>& leaves)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.first.assign(leaves.size() + 1, 0);
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    unsigned long long n = 0;
    for (std::uint64_t word : leaves[l].mask) n += std::uint64_t(__builtin_popcountll(word));
    st.first[l + 1] = st.first[l] + n;
  }
  st.nodes = st.first.back();
  if (st.nodes == 0) return;
  cudaStream_t stream = st.stream.s;
  const std::size_t n = std::size_t(table.all.count);
  const std::size_t cells = std::size_t(table.dim[0]) * table.dim[1] * table.dim[2] + 1;
  // Host-to-device copies from pageable memory return once staged: the sources may go.
  auto up = [&](const double* host) {
    return std::make_unique<DeviceArray<double>>(host, n, stream);
  };
  st.x = up(table.all.x);
  st.y = up(table.all.y);
  st.z = up(table.all.z);
  st.nx = up(table.all.nx);
  st.ny = up(table.all.ny);
  st.nz = up(table.all.nz);
  st.w = up(table.all.w);
  st.id = std::make_unique<DeviceArray<std::int32_t>>(table.all.id, n, stream);
  st.starts = std::make_unique<DeviceArray<std::int32_t>>(table.cell_start, cells, stream);
  st.far_face = std::make_unique<DeviceArray<std::uint8_t>>(table.far_face, n, stream);
  st.tasks = std::make_unique<DeviceArray<LeafTask>>(leaves.data(), leaves.size(), stream);
  st.firsts = std::make_unique<DeviceArray<unsigned long long>>(st.first.data(), st.first.size(),
                                                                stream);
  st.out = std::make_unique<DeviceArray<NodeValue>>(st.nodes);
  CellTable device = table;
  device.all = SampleSpan{st.x->ptr, st.y->ptr, st.z->ptr, st.nx->ptr, st.ny->ptr, st.nz->ptr,
                          st.w->ptr, st.id->ptr, table.all.count, 0};
  device.cell_start = st.starts->ptr;
  device.far_face = st.far_face->ptr;
  nodeKernel<<<unsigned(leaves.size()), 512, 0, stream>>>(device, job, st.tasks->ptr,
                                                          st.firsts->ptr, st.out->ptr);
  FIELDPATH_CUDA_CHECK(cudaGetLastError());
}

CudaNodeBuild::~CudaNodeBuild() {
  if (state_ && state_->stream.s)  // before the frees
    FIELDPATH_CUDA_WARN(cudaStreamSynchronize(state_->stream.s));
}

NodeValues CudaNodeBuild::finish() {
  State& st = *state_;
  NodeValues values(st.nodes);  // not zeroed
  if (st.nodes == 0) return values;
  FIELDPATH_CUDA_CHECK(cudaMemcpyAsync(values.data(), st.out->ptr, st.nodes * sizeof(NodeValue),
                                cudaMemcpyDeviceToHost, st.stream.s));
  FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(st.stream.s));
  return values;
}

}  // namespace fieldpath::field::kernel
