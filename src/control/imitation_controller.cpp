#include "pinball/control/imitation_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace pinball::control {

namespace {

constexpr double kPi = 3.14159265358979323846;

std::size_t line_index(int flipper, bool rolling) {
  return static_cast<std::size_t>(flipper) * 2 + (rolling ? 1 : 0);
}

// Median of the first n values (n >= 1); reorders them.
double median(double* v, int n) {
  std::sort(v, v + n);
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

// The k nearest so far, sorted by (distance, index).
struct ShotTable::Neighbours {
  std::array<double, kMaxNeighbours> d2{};
  std::array<std::uint32_t, kMaxNeighbours> index{};
  int found = 0;
  int k = 1;
  bool full() const { return found == k; }
  double worst() const { return d2[static_cast<std::size_t>(found - 1)]; }
  void offer(double dist2, std::uint32_t i) {
    auto before = [&](int j) {  // does (dist2, i) sort before slot j?
      const auto s = static_cast<std::size_t>(j);
      return dist2 < d2[s] || (dist2 == d2[s] && i < index[s]);
    };
    if (full() && !before(k - 1)) return;
    int j = full() ? k - 1 : found++;
    while (j > 0 && before(j - 1)) {
      d2[static_cast<std::size_t>(j)] = d2[static_cast<std::size_t>(j - 1)];
      index[static_cast<std::size_t>(j)] = index[static_cast<std::size_t>(j - 1)];
      --j;
    }
    d2[static_cast<std::size_t>(j)] = dist2;
    index[static_cast<std::size_t>(j)] = i;
  }
};

ShotTable::ShotTable(std::vector<ShotExample> examples, const ImitationConfig& config)
    : examples_(std::move(examples)), config_(config) {
  if (config.neighbours < 1 || config.neighbours > kMaxNeighbours) {
    throw std::invalid_argument("shot table: neighbours must be in [1, " + std::to_string(kMaxNeighbours) + "]");
  }
  if (!(config.angle_scale_rad > 0.0 && config.h_scale > 0.0 && config.speed_scale_mps > 0.0)) {
    throw std::invalid_argument("shot table: the distance scales must be > 0");
  }
  if (!(config.max_hold_s >= 0.0)) throw std::invalid_argument("shot table: max hold must be >= 0");
  if (!(config.lead_s >= 0.0 && config.lead_s < 1.0)) throw std::invalid_argument("shot table: lead must be in [0, 1) s");
  if (examples_.size() >= std::numeric_limits<std::uint32_t>::max()) throw std::invalid_argument("shot table: too many examples");
  std::array<std::vector<std::uint32_t>, 4> members;
  for (std::size_t i = 0; i < examples_.size(); ++i) {
    const ShotExample& e = examples_[i];
    const std::string where = "shot table: example " + std::to_string(i) + ": ";
    if (e.flipper != track::kLeftFlipper && e.flipper != track::kRightFlipper) {
      throw std::invalid_argument(where + "flipper must be 0 (left) or 1 (right)");
    }
    if (e.fired_flipper < -1 || e.fired_flipper > 1) {
      throw std::invalid_argument(where + "fired flipper must be -1 (pass), 0 or 1");
    }
    if (!std::isfinite(e.angle_rad) || !std::isfinite(e.h) || !std::isfinite(e.speed_mps) ||
        !std::isfinite(e.d_fire_m) || !std::isfinite(e.hold_s)) {
      throw std::invalid_argument(where + "numbers must be finite");
    }
    if (e.hold_s < 0.0) throw std::invalid_argument(where + "hold must be >= 0");
    members[line_index(e.flipper, e.rolling)].push_back(static_cast<std::uint32_t>(i));
  }
  for (std::size_t l = 0; l < lines_.size(); ++l) build_line(lines_[l], members[l]);
}

namespace {

int clamp_cell(double x, int n) {
  if (!(x > 0.0)) return 0;  // also NaN
  return x >= n - 1 ? n - 1 : static_cast<int>(x);
}

// θ folded to [0, π) for the θ axis (the distance is taken modulo π anyway).
double theta_position(double angle_rad) {
  double t = std::fmod(angle_rad + 0.5 * kPi, kPi);
  if (t < 0.0) t += kPi;
  return t;
}

}  // namespace

void ShotTable::build_line(Line& line, const std::vector<std::uint32_t>& members) {
  line.n_theta = std::max(1, static_cast<int>(std::floor(kPi / config_.angle_scale_rad)));
  line.cell_theta_rad = kPi / line.n_theta;
  double h_min = 0.0, h_max = 0.0, s_min = 0.0, s_max = 0.0;
  for (std::size_t j = 0; j < members.size(); ++j) {
    const ShotExample& e = examples_[members[j]];
    h_min = j == 0 ? e.h : std::min(h_min, e.h);
    h_max = j == 0 ? e.h : std::max(h_max, e.h);
    s_min = j == 0 ? e.speed_mps : std::min(s_min, e.speed_mps);
    s_max = j == 0 ? e.speed_mps : std::max(s_max, e.speed_mps);
  }
  // Cells one scale wide; a pathological spread is capped (cells get wider, the search stays exact).
  constexpr double kMaxCellsPerAxis = 512.0;
  line.h0 = h_min;
  line.s0 = s_min;
  line.n_h = static_cast<int>(std::min(kMaxCellsPerAxis, std::floor((h_max - h_min) / config_.h_scale) + 1.0));
  line.n_s = static_cast<int>(std::min(kMaxCellsPerAxis, std::floor((s_max - s_min) / config_.speed_scale_mps) + 1.0));
  const std::size_t cells = static_cast<std::size_t>(line.n_theta) * line.n_h * line.n_s;
  std::vector<std::uint32_t> cell(members.size());
  line.start.assign(cells + 1, 0);
  for (std::size_t j = 0; j < members.size(); ++j) {
    const ShotExample& e = examples_[members[j]];
    cell[j] = static_cast<std::uint32_t>(
        cell_of(line, clamp_cell(theta_position(e.angle_rad) / line.cell_theta_rad, line.n_theta),
                clamp_cell((e.h - line.h0) / config_.h_scale, line.n_h),
                clamp_cell((e.speed_mps - line.s0) / config_.speed_scale_mps, line.n_s)));
    ++line.start[cell[j] + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) line.start[c + 1] += line.start[c];
  line.items.assign(members.size(), 0);
  std::vector<std::uint32_t> fill(line.start.begin(), line.start.end() - 1);
  for (std::size_t j = 0; j < members.size(); ++j) line.items[fill[cell[j]]++] = members[j];
}

int ShotTable::cell_of(const Line& line, int it, int ih, int is) const {
  return (it * line.n_h + ih) * line.n_s + is;
}

void ShotTable::consider(std::uint32_t i, const track::TrajectoryProjection& p, Neighbours& n) const {
  const ShotExample& e = examples_[i];
  const double da = std::remainder(e.angle_rad - p.angle_rad, kPi) / config_.angle_scale_rad;
  const double dh = (e.h - p.h) / config_.h_scale;
  const double ds = (e.speed_mps - p.speed_mps) / config_.speed_scale_mps;
  n.offer(da * da + dh * dh + ds * ds, i);
}

ImitationDecision ShotTable::vote(const Neighbours& n) const {
  ImitationDecision out;
  out.neighbours = n.found;
  std::array<double, kMaxNeighbours> d{};
  std::array<double, kMaxNeighbours> hold{};
  int fired = 0;
  std::array<int, 2> per_flipper{};
  for (int j = 0; j < n.found; ++j) {
    const ShotExample& e = examples_[n.index[static_cast<std::size_t>(j)]];
    if (e.fired_flipper < 0) continue;
    d[static_cast<std::size_t>(fired)] = e.d_fire_m;
    hold[static_cast<std::size_t>(fired)] = e.hold_s;
    ++per_flipper[static_cast<std::size_t>(e.fired_flipper)];
    ++fired;
  }
  if (n.found == 0 || 2 * fired <= n.found) return out;  // a tie passes: the teacher's default
  out.fire = true;
  out.flipper = per_flipper[1] > per_flipper[0] ? track::kRightFlipper : track::kLeftFlipper;
  out.d_critical_m = median(d.data(), fired);
  out.hold_s = median(hold.data(), fired);
  return out;
}

ImitationDecision ShotTable::decide_by_scan(const track::TrajectoryProjection& p) const {
  Neighbours n;
  n.k = config_.neighbours;
  const Line& line = lines_[line_index(p.flipper == track::kRightFlipper ? 1 : 0, p.rolling)];
  for (const std::uint32_t i : line.items) consider(i, p, n);
  return vote(n);
}

ImitationDecision ShotTable::decide(const track::TrajectoryProjection& p) const {
  // No allocation on the control path: fixed arrays, and shells of cells.
  Neighbours n;
  n.k = config_.neighbours;
  const Line& line = lines_[line_index(p.flipper == track::kRightFlipper ? 1 : 0, p.rolling)];
  if (line.items.empty()) return vote(n);
  const int qt = clamp_cell(theta_position(p.angle_rad) / line.cell_theta_rad, line.n_theta);
  const int qh = clamp_cell((p.h - line.h0) / config_.h_scale, line.n_h);
  const int qs = clamp_cell((p.speed_mps - line.s0) / config_.speed_scale_mps, line.n_s);
  // θ offsets that reach each θ cell exactly once around the circle.
  const int t_lo = -(line.n_theta - 1) / 2;
  const int t_hi = line.n_theta - 1 + t_lo;
  const int r_max = std::max({t_hi, -t_lo, line.n_h, line.n_s});
  for (int r = 0; r <= r_max; ++r) {
    for (int dt = std::max(-r, t_lo); dt <= std::min(r, t_hi); ++dt) {
      const int it = ((qt + dt) % line.n_theta + line.n_theta) % line.n_theta;
      for (int dh = -r; dh <= r; ++dh) {
        const int ih = qh + dh;
        if (ih < 0 || ih >= line.n_h) continue;
        const bool edge_th = std::abs(dt) == r || std::abs(dh) == r;
        for (int ds = -r; ds <= r; ds += (edge_th ? 1 : 2 * std::max(r, 1))) {  // inside the shell: only ds = ±r
          const int is = qs + ds;
          if (is < 0 || is >= line.n_s) continue;
          const int c = cell_of(line, it, ih, is);
          for (std::uint32_t j = line.start[static_cast<std::size_t>(c)]; j < line.start[static_cast<std::size_t>(c) + 1]; ++j) {
            consider(line.items[j], p, n);
          }
        }
      }
    }
    // Every example not yet seen lies at least r cells (each at least one scale wide) away.
    if (n.full() && n.worst() < static_cast<double>(r) * static_cast<double>(r)) break;
  }
  return vote(n);
}

ImitationController::ImitationController(std::shared_ptr<const ShotTable> table) : table_(std::move(table)) {
  if (table_ == nullptr) throw std::invalid_argument("imitation controller: no shot table");
}

void ImitationController::reset(std::array<bool, 2>& energized) {
  energized = {false, false};
  held_ = -1;
}

void ImitationController::update(const track::TrackerOutput& out, double now_s, std::array<bool, 2>& energized) {
  if (out.launch.launched || out.launch.lost) {
    reset(energized);
    return;
  }
  if (held_ >= 0) {
    const double max_hold = table_->config().max_hold_s;
    if (now_s + 1e-6 < release_at_s_ && (max_hold <= 0.0 || now_s - held_since_s_ <= max_hold)) return;
    energized[static_cast<std::size_t>(held_)] = false;  // the hold is over: the next decision is a new one
    held_ = -1;
    return;
  }
  const track::TrajectoryProjection& p = out.projection;
  if (!p.valid || !p.hittable) return;
  const ImitationDecision act = table_->decide(p);
  if (!act.fire || p.d_m - p.speed_mps * table_->config().lead_s > act.d_critical_m) return;
  energized[static_cast<std::size_t>(act.flipper)] = true;
  held_ = act.flipper;
  held_since_s_ = now_s;
  release_at_s_ = now_s + act.hold_s;
  ++fires_;
}

}  // namespace pinball::control
