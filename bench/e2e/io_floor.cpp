// The I/O floor of a batch conversion: read every input file in full and write the same
// number of output files with the same sizes, doing nothing else. bench/e2e/convert_batch.sh
// compares `brdf convert` with it.
//
//   io_floor [--durable] [--jobs N] INPUT_DIR SIZES_FILE OUT_DIR
//
// SIZES_FILE lists one output file size in bytes per line (the sizes `brdf convert` wrote).
// Inputs are read through a 1 MiB buffer; outputs are written from a buffer of non-zero bytes.
// --durable writes each output the way the exporters do (brdf::AtomicOutputPath: a temporary
// sibling, fsync, rename into place, fsync of the folder), so the floor carries the same
// durability cost. Work is split over N threads (inputs and outputs round-robin). Prints the
// wall time in seconds, the bytes read and the bytes written.
#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

[[noreturn]] void Die(const std::string& message) {
  std::fprintf(stderr, "io_floor: %s\n", message.c_str());
  std::exit(1);
}

std::uint64_t ReadWhole(const std::string& path, std::vector<char>& buffer) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) Die("cannot open " + path);
  std::uint64_t total = 0;
  for (;;) {
    const ssize_t n = ::read(fd, buffer.data(), buffer.size());
    if (n < 0) Die("cannot read " + path);
    if (n == 0) break;
    total += static_cast<std::uint64_t>(n);
  }
  ::close(fd);
  return total;
}

void WriteFile(const fs::path& path, std::uint64_t size, const std::vector<char>& data,
               bool durable) {
  const fs::path temp = path.parent_path() / ("." + path.filename().string() + ".tmp");
  const std::string target = durable ? temp.string() : path.string();
  const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) Die("cannot create " + target);
  for (std::uint64_t done = 0; done < size;) {
    const std::size_t chunk =
        static_cast<std::size_t>(std::min<std::uint64_t>(size - done, data.size()));
    const ssize_t n = ::write(fd, data.data(), chunk);
    if (n <= 0) Die("cannot write " + target);
    done += static_cast<std::uint64_t>(n);
  }
  if (durable && ::fsync(fd) != 0) Die("fsync failed on " + target);
  ::close(fd);
  if (durable) {
    if (std::rename(temp.c_str(), path.c_str()) != 0) Die("cannot rename " + target);
    const int dir = ::open(path.parent_path().c_str(), O_RDONLY);
    if (dir >= 0) {
      ::fsync(dir);
      ::close(dir);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool durable = false;
  int jobs = 1;
  std::vector<std::string> positional;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--durable") {
      durable = true;
    } else if (a == "--jobs" && i + 1 < argc) {
      jobs = std::max(1, std::atoi(argv[++i]));
    } else {
      positional.push_back(a);
    }
  }
  if (positional.size() != 3)
    Die("usage: io_floor [--durable] [--jobs N] INPUT_DIR SIZES_FILE OUT_DIR");
  std::vector<std::string> inputs;
  for (const auto& e : fs::directory_iterator(positional[0]))
    if (e.is_regular_file()) inputs.push_back(e.path().string());
  std::vector<std::uint64_t> sizes;
  {
    std::ifstream in(positional[1]);
    for (std::uint64_t s; in >> s;) sizes.push_back(s);
  }
  const fs::path out = positional[2];
  fs::create_directories(out);

  std::atomic<std::uint64_t> read_bytes{0}, written_bytes{0};
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int t = 0; t < jobs; ++t)
    pool.emplace_back([&, t] {
      std::vector<char> buffer(1 << 20);
      std::vector<char> data(1 << 20);
      for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<char>(i * 131 + 7);
      // Interleave reading and writing as a converter does: input i, then its share of outputs.
      const std::size_t per_input =
          inputs.empty() ? sizes.size() : (sizes.size() + inputs.size() - 1) / inputs.size();
      for (std::size_t i = static_cast<std::size_t>(t); i < std::max(inputs.size(), std::size_t{1});
           i += static_cast<std::size_t>(jobs)) {
        if (i < inputs.size()) read_bytes += ReadWhole(inputs[i], buffer);
        for (std::size_t o = i * per_input; o < std::min(sizes.size(), (i + 1) * per_input); ++o) {
          WriteFile(out / ("out_" + std::to_string(o)), sizes[o], data, durable);
          written_bytes += sizes[o];
        }
      }
    });
  for (auto& th : pool) th.join();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%.6f %llu %llu\n", seconds, static_cast<unsigned long long>(read_bytes.load()),
              static_cast<unsigned long long>(written_bytes.load()));
  return 0;
}
