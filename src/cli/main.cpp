#include <iostream>

#include "commands.h"

int main(int argc, char** argv) { return pinball::cli::run_pinball(argc, argv, std::cout, std::cerr); }
