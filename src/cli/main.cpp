#include <csignal>
#include <iostream>
#include <sstream>

#include "commands.h"
#include "pinball/core/file_sink.h"
#include "pinball/learn/team.h"

int main(int argc, char** argv) {
  // A closed pipe (`pinball ... | head`, a trace to a pipe whose reader left) is then a failed
  // write that the command sees, not a death by SIGPIPE in the middle of writing a file.
  std::signal(SIGPIPE, SIG_IGN);
  // Under mpirun every rank runs the same command (docs/learning.md, "Across machines").
  const pinball::learn::TeamSession team(argc, argv);
  if (pinball::learn::team_root()) {
    return pinball::exit_status_after_stdout("pinball", pinball::cli::run_pinball(argc, argv, std::cout, std::cerr));
  }
  // The other ranks print nothing: rank 0 has the same figures. Their errors
  // are shown, marked, should one fail where rank 0 did not.
  std::ostringstream quiet_out;
  std::ostringstream quiet_err;
  const int code = pinball::cli::run_pinball(argc, argv, quiet_out, quiet_err);
  if (code != 0) {
    std::cerr << "pinball (rank " << pinball::learn::team_rank() << " of " << pinball::learn::team_size()
              << "): " << quiet_err.str();
  }
  return code;
}
