#include "pinball/control/imitation_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pinball::control {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Bounds of a shot's numbers (check_shot_example).
constexpr double kMaxShotH = 100.0;        // flipper lengths
constexpr double kMaxShotSpeed_mps = 100.0;
constexpr double kMaxShotD_m = 10.0;

// Lookup settings (check_imitation_config).
constexpr double kMinScale = 1e-3;
constexpr double kMaxHScale = 10.0;
constexpr double kMaxSpeedScale_mps = 100.0;
constexpr double kMaxLead_s = 0.1;  // 20 frames at 200 fps: more is no lead for one frame

// "must be in [lo, hi]<unit>" when lo <= x <= hi fails (NaN fails too).
RangeViolation outside(const char* key, double x, double lo, double hi, const char* unit) {
  if (x >= lo && x <= hi) return {};
  std::ostringstream rule;
  rule << "must be in [" << lo << ", " << hi << "]" << unit;
  return {key, rule.str()};
}

// The first violation of a list, or none.
RangeViolation first_of(std::initializer_list<RangeViolation> checks) {
  for (const RangeViolation& v : checks) {
    if (v) return v;
  }
  return {};
}

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

RangeViolation check_imitation_config(const ImitationConfig& c) {
  if (c.neighbours < 1 || c.neighbours > kMaxNeighbours) {
    return {"neighbours", "must be in [1, " + std::to_string(kMaxNeighbours) + "]"};
  }
  return first_of({outside("angle_scale_rad", c.angle_scale_rad, kMinScale, kPi, " rad"),
                   outside("h_scale", c.h_scale, kMinScale, kMaxHScale, " flipper lengths"),
                   outside("speed_scale_mps", c.speed_scale_mps, kMinScale, kMaxSpeedScale_mps, " m/s"),
                   outside("max_hold_s", c.max_hold_s, 0.0, kMaxHold_s, " s (0: no limit of its own)"),
                   outside("lead_s", c.lead_s, 0.0, kMaxLead_s, " s"),
                   check_lead_actuation_delay(c.lead_actuation_delay_s)});
}

RangeViolation check_shot_example(const ShotExample& e) {
  if (e.flipper != track::kLeftFlipper && e.flipper != track::kRightFlipper) {
    return {"flipper", "must be 0 (left) or 1 (right)"};
  }
  if (e.fired_flipper < -1 || e.fired_flipper > 1) return {"fired_flipper", "must be -1 (pass), 0 or 1"};
  return first_of({outside("angle_rad", e.angle_rad, -kPi, kPi, " rad"),
                   outside("h", e.h, -kMaxShotH, kMaxShotH, " flipper lengths"),
                   outside("speed_mps", e.speed_mps, 0.0, kMaxShotSpeed_mps, " m/s"),
                   outside("d_fire_m", e.d_fire_m, -kMaxShotD_m, kMaxShotD_m, " m"),
                   outside("hold_s", e.hold_s, 0.0, kMaxHold_s, " s")});
}

ShotTable::ShotTable(std::vector<ShotExample> examples, const ImitationConfig& config)
    : examples_(std::move(examples)), config_(config) {
  check_input(check_imitation_config(config), "shot table");
  check_input(examples_.size() <= kMaxShots, "shot table", "more than " + std::to_string(kMaxShots) + " shots");
  std::array<std::vector<std::uint32_t>, 4> members;
  for (std::size_t i = 0; i < examples_.size(); ++i) {
    const ShotExample& e = examples_[i];
    check_input(check_shot_example(e), "shot table: example " + std::to_string(i));
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

// Halves the longest axis until the grid has at most `max_cells` cells. Cells
// only get wider, so every unseen example stays at least r cells, each at
// least one scale wide, away after shell r, and the search stays exact.
void fit_grid(int& a, int& b, int& c, std::size_t max_cells) {
  while (static_cast<std::size_t>(a) * static_cast<std::size_t>(b) * static_cast<std::size_t>(c) > max_cells) {
    int& longest = a >= b && a >= c ? a : (b >= c ? b : c);
    longest = (longest + 1) / 2;
  }
}

}  // namespace

void ShotTable::build_line(Line& line, const std::vector<std::uint32_t>& members) {
  // The scales are bounded (check_imitation_config), so the cast is safe: at most π / 0.001 cells.
  line.n_theta = std::max(1, static_cast<int>(std::floor(kPi / config_.angle_scale_rad)));
  double h_min = 0.0, h_max = 0.0, s_min = 0.0, s_max = 0.0;
  for (std::size_t j = 0; j < members.size(); ++j) {
    const ShotExample& e = examples_[members[j]];
    h_min = j == 0 ? e.h : std::min(h_min, e.h);
    h_max = j == 0 ? e.h : std::max(h_max, e.h);
    s_min = j == 0 ? e.speed_mps : std::min(s_min, e.speed_mps);
    s_max = j == 0 ? e.speed_mps : std::max(s_max, e.speed_mps);
  }
  // Cells one scale wide, at most 512 a side and not many more cells than
  // examples: a sparse table gets wider cells, not a grid of empty ones.
  constexpr double kMaxCellsPerAxis = 512.0;
  line.h0 = h_min;
  line.s0 = s_min;
  line.n_theta = std::min(line.n_theta, static_cast<int>(kMaxCellsPerAxis));
  line.n_h = static_cast<int>(std::min(kMaxCellsPerAxis, std::floor((h_max - h_min) / config_.h_scale) + 1.0));
  line.n_s = static_cast<int>(std::min(kMaxCellsPerAxis, std::floor((s_max - s_min) / config_.speed_scale_mps) + 1.0));
  fit_grid(line.n_theta, line.n_h, line.n_s, std::max<std::size_t>(64, 2 * members.size()));
  line.cell_theta_rad = kPi / line.n_theta;
  line.cell_h = std::max(config_.h_scale, (h_max - h_min) / line.n_h);
  line.cell_s = std::max(config_.speed_scale_mps, (s_max - s_min) / line.n_s);
  const std::size_t cells = static_cast<std::size_t>(line.n_theta) * line.n_h * line.n_s;
  std::vector<std::uint32_t> cell(members.size());
  line.start.assign(cells + 1, 0);
  for (std::size_t j = 0; j < members.size(); ++j) {
    const ShotExample& e = examples_[members[j]];
    cell[j] = static_cast<std::uint32_t>(
        cell_of(line, clamp_cell(theta_position(e.angle_rad) / line.cell_theta_rad, line.n_theta),
                clamp_cell((e.h - line.h0) / line.cell_h, line.n_h),
                clamp_cell((e.speed_mps - line.s0) / line.cell_s, line.n_s)));
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
  const int qh = clamp_cell((p.h - line.h0) / line.cell_h, line.n_h);
  const int qs = clamp_cell((p.speed_mps - line.s0) / line.cell_s, line.n_s);
  // θ offsets that reach each θ cell exactly once around the circle.
  const int t_lo = -(line.n_theta - 1) / 2;
  const int t_hi = line.n_theta - 1 + t_lo;
  const int r_max = std::max({t_hi, -t_lo, line.n_h, line.n_s});
  // The work is bounded: a step is a row of cells, a cell or a shot
  // considered, and once the steps outnumber the line's shots a scan of the
  // line is the cheaper way to finish, so a decision costs at most about two
  // scans (a sparse table, whose shots lie many empty cells from the query,
  // once took 40 ms for one decision). The loops stay inside the grid.
  const std::size_t budget = line.items.size() + 64;
  std::size_t steps = 0;
  auto visit = [&](int it, int ih, int is) {
    const auto c = static_cast<std::size_t>(cell_of(line, it, ih, is));
    for (std::uint32_t j = line.start[c]; j < line.start[c + 1]; ++j) consider(line.items[j], p, n);
    steps += 1 + (line.start[c + 1] - line.start[c]);
  };
  for (int r = 0; r <= r_max; ++r) {
    for (int dt = std::max(-r, t_lo); dt <= std::min(r, t_hi); ++dt) {
      const int it = ((qt + dt) % line.n_theta + line.n_theta) % line.n_theta;
      for (int dh = std::max(-r, -qh); dh <= std::min(r, line.n_h - 1 - qh); ++dh) {
        const int ih = qh + dh;
        ++steps;
        if (std::abs(dt) == r || std::abs(dh) == r) {  // a face of the shell: every s cell in reach
          for (int ds = std::max(-r, -qs); ds <= std::min(r, line.n_s - 1 - qs); ++ds) visit(it, ih, qs + ds);
        } else {  // inside the shell: only s = ±r
          if (qs - r >= 0) visit(it, ih, qs - r);
          if (qs + r < line.n_s) visit(it, ih, qs + r);
        }
        if (steps > budget) return decide_by_scan(p);
      }
    }
    // Every example not yet seen lies more than r cells (each at least one scale wide) away.
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
  const track::TrajectoryProjection p = projection_to_act_on(out, table_->config().lead_actuation_delay_s);
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
