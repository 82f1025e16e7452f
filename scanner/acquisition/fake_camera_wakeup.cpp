#include "scanner/acquisition/fake_camera_wakeup.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <system_error>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::acquisition {
namespace {

constexpr std::uint16_t kGvcpPort = 3956;
constexpr std::uint8_t kGvcpKey = 0x42;  // every GVCP command starts with it
constexpr std::uint16_t kReadRegisterCommand = 0x0080;

// A GVCP READREG_CMD of register 0, no acknowledge asked: header (key, flags, command, length,
// request id) and one big-endian register address.
std::array<std::uint8_t, 12> ReadVersionRegister(std::uint16_t request_id) {
  return {kGvcpKey,
          0x00,
          0x00,
          static_cast<std::uint8_t>(kReadRegisterCommand),
          0x00,
          0x04,
          static_cast<std::uint8_t>(request_id >> 8),
          static_cast<std::uint8_t>(request_id & 0xff),
          0x00,
          0x00,
          0x00,
          0x00};
}

}  // namespace

FakeCameraWakeup::FakeCameraWakeup(std::uint32_t ipv4_host_order, int period_us) {
  socket_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (socket_ < 0)
    throw Error(std::string("fake camera: cannot open a UDP socket (") + std::strerror(errno) +
                ")");
  try {
    thread_ = std::thread([this, ipv4_host_order, period_us] { Run(ipv4_host_order, period_us); });
  } catch (const std::system_error& e) {
    ::close(socket_);
    throw Error(std::string("fake camera: cannot start the wake-up thread (") + e.what() + ")");
  }
}

FakeCameraWakeup::~FakeCameraWakeup() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  ::close(socket_);
}

void FakeCameraWakeup::Run(std::uint32_t ipv4_host_order, int period_us) {
  sockaddr_in camera{};
  camera.sin_family = AF_INET;
  camera.sin_port = htons(kGvcpPort);
  camera.sin_addr.s_addr = htonl(ipv4_host_order);
  std::array<std::uint8_t, 64> reply{};
  std::uint16_t request_id = 1;
  while (!stop_) {
    const auto packet = ReadVersionRegister(request_id);
    request_id = request_id == 0xffff ? 1 : request_id + 1;  // 0 is not a valid request id
    ::sendto(socket_, packet.data(), packet.size(), 0, reinterpret_cast<const sockaddr*>(&camera),
             sizeof camera);
    // The camera may answer anyway: drop what came back.
    while (::recv(socket_, reply.data(), reply.size(), 0) > 0) {
    }
    std::this_thread::sleep_for(std::chrono::microseconds(period_us));
  }
}

}  // namespace uwscan::scanner::acquisition
