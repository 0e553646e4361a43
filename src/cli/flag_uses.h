#pragma once
// Flags that only some variants of a command read (bench's benches,
// calibrate's kinds): a flag given to a variant that would ignore it is
// refused, so that `bench tracker --noise-px 1` or `calibrate latency
// --sim-rolls 9` does not quietly run without it.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pinball::cli {

/// The variants that read each of `flags` ("--steps" read by "speed").
struct FlagUse {
  std::vector<std::string_view> flags;
  std::vector<std::string_view> variants;
};

/// Records in `given` the long flags on `cmd`'s command line ("--noise-px")
/// once it is parsed.
inline void record_flags_given(CLI::App* cmd, std::vector<std::string>& given) {
  cmd->parse_complete_callback([cmd, &given] {
    given.clear();
    for (const CLI::Option* option : cmd->get_options()) {
      if (option->count() > 0 && !option->get_lnames().empty()) given.push_back("--" + option->get_lnames().front());
    }
  });
}

/// "cradle", "ceiling and aim", "ceiling, aim, cradle and transfer".
inline std::string list_in_words(const std::vector<std::string_view>& items) {
  std::string text;
  for (std::size_t i = 0; i < items.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == items.size() ? " and " : ", ") + std::string(items[i]);
  }
  return text;
}

/// Throws std::invalid_argument "`command` `variant`: --flag applies to A and
/// B only" for the first flag of `given` that `uses` gives to other variants.
inline void refuse_flags_not_read(const std::vector<std::string>& given, const std::vector<FlagUse>& uses,
                                  std::string_view command, std::string_view variant) {
  for (const std::string& flag : given) {
    for (const FlagUse& use : uses) {
      if (std::ranges::find(use.flags, flag) == use.flags.end()) continue;
      if (std::ranges::find(use.variants, variant) == use.variants.end()) {
        throw std::invalid_argument(std::string(command) + " " + std::string(variant) + ": " + flag + " applies to " +
                                    list_in_words(use.variants) + " only");
      }
    }
  }
}

}  // namespace pinball::cli
