// The cuda variant: the kernels of kernels.hpp as CUDA grids on device 0, through GpuVariant
// (gpu_variant.hpp). Compiled by nvcc with no FMA contraction (--fmad=false), IEEE division and square
// root, no flush to zero (variants/cuda/cuda.cmake), so each thread's arithmetic is the host's,
// operation for operation; docs/cuda.md says why the trajectory is then arrays' bit for bit.
#include <cuda_runtime.h>

#include <cub/device/device_radix_sort.cuh>

#include <string>
#include <utility>
#include <vector>

#include "demmat/error.hpp"
#include "demmat/registry.hpp"
#include "gpu_variant.hpp"

namespace demmat::gpu {
namespace {

void check(cudaError_t e, const char* what)
{
    if (e != cudaSuccess) throw Error(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(e));
}

constexpr unsigned kThreads = 128;

template <class Body>
__global__ void __launch_bounds__(kThreads) run_body(Body body)
{
    body(blockIdx.x, threadIdx.x, blockDim.x);
}

class DeviceBackend {
public:
    DeviceBackend() = default;
    DeviceBackend(const DeviceBackend&) = delete;
    DeviceBackend& operator=(const DeviceBackend&) = delete;
    DeviceBackend(DeviceBackend&& o) noexcept : ptrs_(std::move(o.ptrs_)), bytes_(o.bytes_), temp_(o.temp_), temp_bytes_(o.temp_bytes_)
    {
        o.ptrs_.clear();
        o.temp_ = nullptr;
        o.temp_bytes_ = 0;
    }
    ~DeviceBackend() { release(); }

    template <class T>
    T* alloc(std::size_t count)
    {
        const std::size_t b = (count > 0 ? count : 1) * sizeof(T);
        void* p = nullptr;
        check(cudaMalloc(&p, b), "cudaMalloc");
        ptrs_.push_back(p);
        check(cudaMemset(p, 0, b), "cudaMemset");
        bytes_ += count * sizeof(T);
        return static_cast<T*>(p);
    }
    void release()
    {
        for (void* p : ptrs_) cudaFree(p);
        if (temp_) cudaFree(temp_);
        ptrs_.clear();
        bytes_ = 0;
        temp_ = nullptr;
        temp_bytes_ = 0;
    }
    template <class T>
    void upload(T* dst, const T* src, std::size_t count)
    {
        if (count) check(cudaMemcpy(dst, src, count * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy to the device");
    }
    template <class T>
    void download(T* dst, const T* src, std::size_t count) const
    {
        if (count) check(cudaMemcpy(dst, src, count * sizeof(T), cudaMemcpyDeviceToHost), "cudaMemcpy from the device");
    }
    void sync() { check(cudaDeviceSynchronize(), "a kernel"); }
    std::size_t bytes() const { return bytes_ + temp_bytes_; }

    template <class Body>
    void launch(std::uint64_t count, const Body& body)
    {
        if (count == 0) return;
        run_body<<<unsigned((count + kThreads - 1) / kThreads), kThreads>>>(body);
        check(cudaGetLastError(), "a kernel launch");
    }

    // CUB's radix sort (stable, though the keys are distinct and any correct sort gives this order).
    void sort(const std::uint64_t* key, std::uint64_t* key_out, const std::uint32_t* val, std::uint32_t* val_out, std::size_t n,
              int end_bit)
    {
        std::size_t need = 0;
        check(cub::DeviceRadixSort::SortPairs(nullptr, need, key, key_out, val, val_out, n, 0, end_bit), "the sort's size query");
        if (need > temp_bytes_) {
            if (temp_) cudaFree(temp_);
            temp_ = nullptr;
            check(cudaMalloc(&temp_, need), "cudaMalloc");
            temp_bytes_ = need;
        }
        std::size_t have = temp_bytes_;
        check(cub::DeviceRadixSort::SortPairs(temp_, have, key, key_out, val, val_out, n, 0, end_bit), "the sort");
    }

private:
    std::vector<void*> ptrs_;
    std::size_t bytes_ = 0;
    void* temp_ = nullptr;
    std::size_t temp_bytes_ = 0;
};

// "" when device 0 can run this build's code (sm_90 and compute_90 PTX: compute capability 9.0 or later).
std::string device_unavailable()
{
    int count = 0;
    if (const cudaError_t e = cudaGetDeviceCount(&count); e != cudaSuccess)
        return std::string("no usable CUDA device (cudaGetDeviceCount: ") + cudaGetErrorString(e) + ")";
    if (count == 0) return "no CUDA device";
    cudaDeviceProp p{};
    check(cudaGetDeviceProperties(&p, 0), "cudaGetDeviceProperties");
    if (p.major < 9)
        return std::string("device 0 (") + p.name + ") has compute capability " + std::to_string(p.major) + "." +
               std::to_string(p.minor) + "; this build carries sm_90 code and compute_90 PTX";
    return "";
}

} // namespace
} // namespace demmat::gpu

namespace demmat {

void register_variant_cuda(Registry& r)
{
    VariantInfo info{"cuda", "the GPU style on CUDA device 0: cell-ordered device memory, one thread per particle, canonical sums",
                     [] { return gpu::make_dispatching<gpu::DeviceBackend>([] { return gpu::DeviceBackend(); }); }};
    info.unavailable = gpu::device_unavailable;
    r.add(std::move(info));
}

} // namespace demmat
