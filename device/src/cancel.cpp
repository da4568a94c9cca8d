#include "brdf/device/cancel.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <string>

#include "brdf/core/error.h"

namespace brdf::device {

CancelSignal::CancelSignal() : fd_(::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
  if (fd_ < 0)
    throw DeviceError(std::string("cannot create the capture's cancel signal: ") +
                      std::strerror(errno));
}

CancelSignal::~CancelSignal() { ::close(fd_); }

void CancelSignal::Raise() noexcept {
  raised_.store(true);
  const std::uint64_t one = 1;
  const int saved = errno;  // a signal handler must leave errno as it found it
  [[maybe_unused]] const ssize_t n = ::write(fd_, &one, sizeof one);
  errno = saved;
}

void CancelSignal::Reset() noexcept {
  std::uint64_t count = 0;
  while (::read(fd_, &count, sizeof count) > 0) {
  }
  raised_.store(false);
}

bool CancelSignal::Wait(int timeout_ms) const {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!raised()) {
    int wait = -1;
    if (timeout_ms >= 0) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) break;
      wait = static_cast<int>(left);
    }
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, wait);
    if (r < 0 && errno != EINTR) break;
  }
  return raised();
}

}  // namespace brdf::device
