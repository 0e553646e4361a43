#include "display_check.h"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>
#include <optional>
#include <string>

namespace pinball::cli {
namespace {

// Sets an environment variable for a test's scope, then puts back what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value == nullptr) {
      ::unsetenv(name);
    } else {
      ::setenv(name, value, 1);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(DisplayCheck, NamesWhatIsMissingOrDoesNotAnswer) {
  const ScopedEnv wayland("WAYLAND_DISPLAY", nullptr);
  const ScopedEnv qpa("QT_QPA_PLATFORM", nullptr);
  {
    const ScopedEnv display("DISPLAY", nullptr);
    EXPECT_EQ(display_problem(), "DISPLAY is not set");
  }
  {
    const ScopedEnv display("DISPLAY", ":987.0");
    EXPECT_EQ(display_problem(), "DISPLAY :987.0: no X server answers at /tmp/.X11-unix/X987");
  }
  {
    const ScopedEnv display("DISPLAY", "nonsense");
    EXPECT_EQ(display_problem(), "DISPLAY nonsense names no display (host:number)");
  }
  {
    const ScopedEnv display("DISPLAY", ":987");
    const ScopedEnv offscreen("QT_QPA_PLATFORM", "offscreen");  // Qt draws into memory: no server needed
    EXPECT_EQ(display_problem(), "");
  }
}

// A display on another host (an SSH forwarding: localhost:10) is TCP port 6000 + N.
TEST(DisplayCheck, AServerOnTcpAnswersAndAClosedPortDoesNot) {
  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(listener, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  int number = -1;
  for (int n = 900; n < 1000 && number < 0; ++n) {  // ports 6900..6999
    address.sin_port = htons(static_cast<std::uint16_t>(6000 + n));
    if (::bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0) number = n;
  }
  ASSERT_GE(number, 0) << "no free port";
  ASSERT_EQ(::listen(listener, 1), 0);
  const ScopedEnv wayland("WAYLAND_DISPLAY", nullptr);
  const ScopedEnv qpa("QT_QPA_PLATFORM", nullptr);
  const std::string name = "localhost:" + std::to_string(number) + ".0";
  {
    const ScopedEnv display("DISPLAY", name.c_str());
    EXPECT_EQ(display_problem(), "");
  }
  ::close(listener);
  const ScopedEnv display("DISPLAY", name.c_str());
  EXPECT_NE(display_problem().find("no X server answers at localhost:" + std::to_string(6000 + number) +
                                   " (a forwarding that has ended?)"),
            std::string::npos)
      << display_problem();
}

}  // namespace
}  // namespace pinball::cli
