#include <csignal>
#include <iostream>

#include "commands.h"

int main(int argc, char** argv) {
  // A closed pipe (`pinball ... | head`, a trace to a pipe whose reader left) is then a failed
  // write that the command sees, not a death by SIGPIPE in the middle of writing a file.
  std::signal(SIGPIPE, SIG_IGN);
  return pinball::cli::run_pinball(argc, argv, std::cout, std::cerr);
}
