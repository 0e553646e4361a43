#pragma once
// Where the shipped data (boards/, controllers/, config/) is found when a
// relative path does not exist from the working directory: the installed
// copy beside the running program (<prefix>/share/pinball, for an installed
// `pinball` or `pinballd`), then the source tree the program was built from
// (a build-tree binary). `pinball` and `pinballd` both resolve through here,
// so a default such as boards/mit1993.board works from any folder.

#include <string>
#include <vector>

namespace pinball {

/// `path` itself when it is empty, absolute or exists from the working
/// directory; otherwise the first data folder that holds it; otherwise
/// `path` unchanged, so that the error names what the user typed.
std::string find_data_file(const std::string& path);

/// The data folders searched after the working directory, in order (those
/// that exist): <exe>/../share/pinball, then the source tree.
std::vector<std::string> data_dirs();

}  // namespace pinball
