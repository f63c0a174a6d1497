/// The CUDA node build (node_cuda.h): one thread per masked node of a leaf, a block of 512
/// threads per leaf; each thread sums the samples of the cell list around its node (and around
/// the points its surface rule lifts it to) with node_kernel.h's math, the CPU's.
#include <cuda_runtime.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "node_cuda.h"

namespace fieldpath::field::kernel {
namespace {

void check(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                             cudaGetErrorString(status));
}
#define FP_CUDA_CHECK(call) check((call), #call, __FILE__, __LINE__)

/// Device memory freed on scope exit.
template <class T>
struct DeviceArray {
  T* ptr = nullptr;
  explicit DeviceArray(std::size_t n) {
    if (n) FP_CUDA_CHECK(cudaMalloc(&ptr, n * sizeof(T)));
  }
  DeviceArray(const T* host, std::size_t n, cudaStream_t stream) : DeviceArray(n) {
    if (n) FP_CUDA_CHECK(cudaMemcpyAsync(ptr, host, n * sizeof(T), cudaMemcpyHostToDevice, stream));
  }
  ~DeviceArray() {
    if (ptr) cudaFree(ptr);
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
    return cudaGetDeviceCount(&count) == cudaSuccess && count > 0 && cudaFree(nullptr) == cudaSuccess;
  }();
  return available;
}

NodeValues buildNodesCuda(const CellTable& table, const NodeJob& job,
                          const std::vector<LeafTask>& leaves) {
  std::vector<unsigned long long> first(leaves.size() + 1, 0);
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    unsigned long long n = 0;
    for (std::uint64_t word : leaves[l].mask) n += std::uint64_t(__builtin_popcountll(word));
    first[l + 1] = first[l] + n;
  }
  const std::size_t nodes = first.back();
  NodeValues values{std::unique_ptr<NodeValue[]>(new NodeValue[nodes]), nodes};  // not zeroed
  if (nodes == 0) return values;
  cudaStream_t stream;
  FP_CUDA_CHECK(cudaStreamCreate(&stream));
  struct StreamGuard {
    cudaStream_t s;
    ~StreamGuard() { cudaStreamDestroy(s); }
  } guard{stream};
  const std::size_t n = std::size_t(table.all.count);
  const std::size_t cells = std::size_t(table.dim[0]) * table.dim[1] * table.dim[2] + 1;
  DeviceArray<double> x(table.all.x, n, stream), y(table.all.y, n, stream),
      z(table.all.z, n, stream), nx(table.all.nx, n, stream), ny(table.all.ny, n, stream),
      nz(table.all.nz, n, stream), w(table.all.w, n, stream);
  DeviceArray<std::int32_t> id(table.all.id, n, stream), starts(table.cell_start, cells, stream);
  DeviceArray<LeafTask> tasks(leaves.data(), leaves.size(), stream);
  DeviceArray<unsigned long long> firsts(first.data(), first.size(), stream);
  DeviceArray<NodeValue> out(nodes);
  CellTable device = table;
  device.all = SampleSpan{x.ptr, y.ptr, z.ptr, nx.ptr, ny.ptr, nz.ptr, w.ptr, id.ptr,
                          table.all.count, 0};
  device.cell_start = starts.ptr;
  nodeKernel<<<unsigned(leaves.size()), 512, 0, stream>>>(device, job, tasks.ptr, firsts.ptr,
                                                          out.ptr);
  FP_CUDA_CHECK(cudaGetLastError());
  FP_CUDA_CHECK(cudaMemcpyAsync(values.data.get(), out.ptr, nodes * sizeof(NodeValue),
                                cudaMemcpyDeviceToHost, stream));
  FP_CUDA_CHECK(cudaStreamSynchronize(stream));
  return values;
}

}  // namespace fieldpath::field::kernel
