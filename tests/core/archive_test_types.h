#pragma once
// A struct of every kind of field the archives know, for their tests.

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pinball/core/geometry.h"
#include "pinball/core/name_value.h"

namespace pinball::archive_test {

enum class Colour { kRed, kGreen };

struct Inner {
  double x_m = 1.5;
  std::string label = "in";
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(x_m));
    a->Visit(PINBALL_NVP(label));
  }
};

struct Everything {
  bool flag = false;
  int count = 3;
  std::uint8_t small = 7;
  std::int64_t big = -5;
  std::uint64_t seed = 1;
  double g_mps2 = 9.81;
  std::string name = "default";
  Colour colour = Colour::kRed;
  std::vector<double> values{1.0, 2.0};
  std::array<int, 3> triple{1, 2, 3};
  Vec2 p_m = Vec2(0.5, 0.25);
  Inner inner;
  std::vector<Inner> inners;
  std::optional<Inner> maybe;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(flag));
    a->Visit(PINBALL_NVP(count));
    a->Visit(PINBALL_NVP(small));
    a->Visit(PINBALL_NVP(big));
    a->Visit(PINBALL_NVP(seed));
    a->Visit(PINBALL_NVP(g_mps2));
    a->Visit(PINBALL_NVP(name));
    a->Visit(PINBALL_NVP(colour));
    a->Visit(PINBALL_NVP(values));
    a->Visit(PINBALL_NVP(triple));
    a->Visit(PINBALL_NVP(p_m));
    a->Visit(PINBALL_NVP(inner));
    a->Visit(PINBALL_NVP(inners));
    a->Visit(PINBALL_NVP(maybe));
  }
};

}  // namespace pinball::archive_test

template <>
struct pinball::EnumText<pinball::archive_test::Colour> {
  static std::string name(archive_test::Colour c) { return c == archive_test::Colour::kRed ? "red" : "green"; }
  static archive_test::Colour parse(const std::string& s) {
    if (s == "red") return archive_test::Colour::kRed;
    if (s == "green") return archive_test::Colour::kGreen;
    throw std::invalid_argument("expected red or green");
  }
};
