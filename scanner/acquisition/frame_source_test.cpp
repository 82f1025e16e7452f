#include "scanner/acquisition/frame_source.hpp"

#include <gtest/gtest.h>

#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::acquisition {
namespace {

std::string CheckMessage(const std::string& address) {
  CameraSettings settings;
  settings.address = address;
  try {
    settings.Check();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Only an IPv4 address reaches Aravis: a name (or a typo) would make it search every interface.
TEST(CameraSettings, TheCameraIsGivenByItsIpv4AddressOnly) {
  EXPECT_EQ(CheckMessage("127.0.0.1"), "");
  EXPECT_EQ(CheckMessage("192.168.10.20"), "");
  for (const char* name :
       {"not-an-ip", "camera-1", "127.0.0", "127.0.0.256", "::1", " 127.0.0.1", "Basler-4711"}) {
    const std::string message = CheckMessage(name);
    EXPECT_NE(message.find("CameraSettings.address: expected an IPv4 address"), std::string::npos)
        << name << ": " << message;
    EXPECT_NE(message.find(std::string("got '") + name + "'"), std::string::npos) << message;
  }
  EXPECT_NE(CheckMessage("").find("CameraSettings.address: expected an IPv4 address"),
            std::string::npos);
  EXPECT_NE(CheckMessage("").find("got ''"), std::string::npos);
}

}  // namespace
}  // namespace uwscan::scanner::acquisition
