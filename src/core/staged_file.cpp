#include "pinball/core/staged_file.h"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace pinball {
namespace {

namespace fs = std::filesystem;

// The temporaries alive, for the signal handler: fixed storage, since a handler
// may not allocate. A name too long for a slot is simply not cleaned on a signal.
constexpr std::size_t kSlots = 8;
constexpr std::size_t kNameBytes = 4096;
std::array<std::array<char, kNameBytes>, kSlots> g_temporaries{};
std::array<volatile sig_atomic_t, kSlots> g_in_use{};
constexpr std::array<int, 3> kSignals{SIGINT, SIGTERM, SIGHUP};
std::array<struct sigaction, kSignals.size()> g_previous{};
int g_registered = 0;

void on_signal(int sig) {
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (g_in_use[i]) ::unlink(g_temporaries[i].data());
  }
  for (std::size_t i = 0; i < kSignals.size(); ++i) {
    if (kSignals[i] == sig) ::sigaction(sig, &g_previous[i], nullptr);
  }
  ::raise(sig);  // as it would have: the previous handler, or death by the signal
}

void register_temporary(const std::string& name) {
  if (name.size() >= kNameBytes) return;
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (g_in_use[i]) continue;
    std::memcpy(g_temporaries[i].data(), name.c_str(), name.size() + 1);
    g_in_use[i] = 1;
    if (g_registered++ == 0) {
      struct sigaction on {};
      on.sa_handler = &on_signal;
      sigemptyset(&on.sa_mask);
      for (std::size_t s = 0; s < kSignals.size(); ++s) {
        ::sigaction(kSignals[s], &on, &g_previous[s]);
        // An ignored signal stays ignored (a background job's SIGINT, nohup's SIGHUP).
        if (g_previous[s].sa_handler == SIG_IGN) ::sigaction(kSignals[s], &g_previous[s], nullptr);
      }
    }
    return;
  }
}

void unregister_temporary(const std::string& name) {
  for (std::size_t i = 0; i < kSlots; ++i) {
    if (!g_in_use[i] || name != g_temporaries[i].data()) continue;
    g_in_use[i] = 0;
    if (--g_registered == 0) {
      for (std::size_t s = 0; s < kSignals.size(); ++s) ::sigaction(kSignals[s], &g_previous[s], nullptr);
    }
    return;
  }
}

}  // namespace

StagedFile::StagedFile(std::string path) : path_(std::move(path)), writing_(path_) {
  if (path_.empty()) return;
  std::error_code ec;
  const fs::file_status there = fs::status(path_, ec);
  if (!ec && fs::exists(there) && !fs::is_regular_file(there)) return;  // a device or a pipe: in place
  const fs::path p(path_);
  writing_ = (p.parent_path() / (p.stem().string() + ".partial" + std::to_string(::getpid()) + p.extension().string()))
                 .string();
  staged_ = true;
  register_temporary(writing_);
}

StagedFile::~StagedFile() {
  if (!staged_) return;
  std::error_code ec;
  fs::remove(writing_, ec);
  unregister_temporary(writing_);
}

void StagedFile::commit() {
  if (!staged_) return;
  std::error_code ec;
  fs::rename(writing_, path_, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(writing_, ec);
    unregister_temporary(writing_);
    staged_ = false;
    throw std::runtime_error(path_ + ": cannot write (" + why + ")");
  }
  unregister_temporary(writing_);
  staged_ = false;
}

}  // namespace pinball
