#pragma once
// What a call that should fail says: one helper for the tests that check messages.

#include <stdexcept>
#include <string>

namespace pinball::testing {

/// The what() of the std::runtime_error `call` throws, or "no error" when it returns.
template <class Call>
std::string error_text(Call&& call) {
  try {
    call();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace pinball::testing
