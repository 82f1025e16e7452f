#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

namespace uwscan::scanner::acquisition {

// Works around a stall in Aravis's fake GigE camera (0.8.26, and its main branch as of this
// writing): its stream thread waits for the next frame period in a poll loop whose timeout is
// `(next_timestamp_us - now) / 1000` computed in unsigned arithmetic. When the period's end
// passes between the loop's check and that computation, the difference wraps around, the
// timeout is clamped to 100 ms, and the camera sends nothing for 100 ms (34 frames at 339
// frames/s) unless a control packet wakes it. This sends it a harmless GVCP read of register 0
// (the version) every `period_us`, so that no stall outlasts a frame period.
class FakeCameraWakeup {
 public:
  // ipv4_host_order: the fake camera's address (e.g. 0x7F000001). Throws uwscan::Error when no
  // UDP socket can be opened.
  FakeCameraWakeup(std::uint32_t ipv4_host_order, int period_us);
  ~FakeCameraWakeup();  // stops and joins the thread
  FakeCameraWakeup(const FakeCameraWakeup&) = delete;
  FakeCameraWakeup& operator=(const FakeCameraWakeup&) = delete;

 private:
  void Run(std::uint32_t ipv4_host_order, int period_us);

  int socket_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace uwscan::scanner::acquisition
