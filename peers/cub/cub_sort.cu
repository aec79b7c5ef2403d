// CUB's radix sort, the sort a CUDA user gets, timed as `treelet bench build`
// times Treelet's: random 64-bit keys (or the low 30 bits) with 32-bit values,
// cub::DeviceRadixSort::SortPairs, CUDA events around each sort after a
// warm-up, median of 21. Build: nvcc -O3 -arch=sm_90 cub_sort.cu -o cub_sort
// Run: ./cub_sort 65536,1000000,4000000,16000000   (prints one JSON line per size)
#include <cub/cub.cuh>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

static float median_ms(size_t n, int end_bit) {
    std::mt19937_64 rng(n);
    std::vector<unsigned long long> keys(n);
    for (auto& k : keys) k = end_bit >= 64 ? rng() : rng() & ((1ull << end_bit) - 1);
    std::vector<unsigned> values(n);
    for (size_t i = 0; i < n; ++i) values[i] = (unsigned)i;
    unsigned long long *k_in, *k_out;
    unsigned *v_in, *v_out;
    cudaMalloc(&k_in, n * 8); cudaMalloc(&k_out, n * 8);
    cudaMalloc(&v_in, n * 4); cudaMalloc(&v_out, n * 4);
    cudaMemcpy(k_in, keys.data(), n * 8, cudaMemcpyHostToDevice);
    cudaMemcpy(v_in, values.data(), n * 4, cudaMemcpyHostToDevice);
    size_t temp_bytes = 0;
    cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, k_in, k_out, v_in, v_out, (int)n, 0, end_bit);
    void* temp; cudaMalloc(&temp, temp_bytes);
    cudaEvent_t start, stop; cudaEventCreate(&start); cudaEventCreate(&stop);
    std::vector<float> times;
    for (int r = 0; r < 3 + 21; ++r) {
        cudaEventRecord(start);
        cub::DeviceRadixSort::SortPairs(temp, temp_bytes, k_in, k_out, v_in, v_out, (int)n, 0, end_bit);
        cudaEventRecord(stop);
        cudaEventSynchronize(stop);
        float ms; cudaEventElapsedTime(&ms, start, stop);
        if (r >= 3) times.push_back(ms);
    }
    // Check: sorted output (so a broken call cannot report a time).
    std::vector<unsigned long long> out(n);
    cudaMemcpy(out.data(), k_out, n * 8, cudaMemcpyDeviceToHost);
    if (!std::is_sorted(out.begin(), out.end())) { fprintf(stderr, "CUB output not sorted\n"); exit(1); }
    cudaFree(k_in); cudaFree(k_out); cudaFree(v_in); cudaFree(v_out); cudaFree(temp);
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
}

int main(int argc, char** argv) {
    std::stringstream sizes(argc > 1 ? argv[1] : "65536,1000000,4000000,16000000");
    cudaDeviceProp prop; cudaGetDeviceProperties(&prop, 0);
    for (std::string s; std::getline(sizes, s, ',');) {
        size_t n = std::stoull(s);
        float ms64 = median_ms(n, 64), ms30 = median_ms(n, 30);
        printf("{\"device\": \"%s\", \"n\": %zu, \"cub_sort_ms_64bit\": %.4f, \"cub_sort_ms_30bit\": %.4f}\n", prop.name, n, ms64, ms30);
    }
}
