// Loading the real vendor ESI files of ../shared/esi (config/esi.hpp: XML parse and the model
// of devices, PDOs and dictionaries), one benchmark per file. Counters: the file's size and
// the bytes loaded per second. A figure, not a pass/fail test (tests/config/esi_corpus_test.cpp
// checks what is read). Run: build/default/tests/bench/esi_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "config/esi.hpp"

namespace ecsim {
namespace {

void loadFile(benchmark::State& state, const std::filesystem::path& path) {
  const auto bytes = static_cast<double>(std::filesystem::file_size(path));
  for (auto _ : state) {
    auto file = loadEsiFile(path);
    if (!file.ok()) {
      state.SkipWithError(file.error().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(file->devices.size());
  }
  state.counters["file_kB"] = bytes / 1024.0;
  state.counters["MB_per_s"] = benchmark::Counter(
      bytes * static_cast<double>(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}

}  // namespace
}  // namespace ecsim

int main(int argc, char** argv) {
  const std::filesystem::path dir = std::filesystem::path(ECSIM_SHARED_DIR) / "esi";
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".xml") files.push_back(entry.path());
  }
  if (files.empty()) {
    std::fprintf(stderr, "esi_bench: no ESI files in %s\n", dir.c_str());
    return 1;
  }
  std::sort(files.begin(), files.end());
  for (const auto& path : files) {
    benchmark::RegisterBenchmark(("LoadEsi/" + path.filename().string()).c_str(),
                                 [path](benchmark::State& s) { ecsim::loadFile(s, path); })
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
