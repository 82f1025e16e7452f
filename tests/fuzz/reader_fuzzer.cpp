// One libFuzzer target for every reader of outside data (bench/robustness/reader_probes.hpp): the
// reader is chosen by the environment variable UWSCAN_FUZZ_READER, so one sanitized link serves
// them all. An input may end in a clean uwscan::Error or be accepted; any other exception, a crash,
// a hang or a leak is a finding (libFuzzer stops and keeps the input).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "bench/robustness/reader_probes.hpp"
#include "scanner/common/error.hpp"

namespace {

namespace fs = std::filesystem;

const uwscan::bench::ReaderProbe* g_probe = nullptr;
fs::path g_workspace;
fs::path g_input;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* name = std::getenv("UWSCAN_FUZZ_READER");
  if (name == nullptr) {
    std::fprintf(stderr, "reader_fuzzer: set UWSCAN_FUZZ_READER to a reader name\n");
    std::exit(2);
  }
  try {
    g_probe = &uwscan::bench::FindReaderProbe(name);
  } catch (const uwscan::Error& error) {
    std::fprintf(stderr, "reader_fuzzer: %s\n", error.what());
    std::exit(2);
  }
  // A private workspace: the input file where the reader expects it, beside the scanner files
  // and images that scenes and manifests name. Removed when the fuzzer exits normally.
  g_workspace = fs::temp_directory_path() / ("uwscan_fuzz_" + std::to_string(getpid()));
  try {
    uwscan::bench::PrepareReaderWorkspace(g_workspace, UWSCAN_DATA_DIR);
  } catch (const uwscan::Error& error) {
    std::fprintf(stderr, "reader_fuzzer: %s\n", error.what());
    std::exit(2);
  }
  g_input = uwscan::bench::ReaderInputPath(*g_probe, g_workspace);
  std::atexit([] {
    std::error_code ignored;
    fs::remove_all(g_workspace, ignored);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  {
    std::ofstream out(g_input, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    g_probe->read(g_input);
  } catch (const uwscan::Error&) {
    // A clean refusal: what a reader must do with bad input.
  }
  return 0;
}
