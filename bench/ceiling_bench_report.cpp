// The ceiling bench's report, JSON and text (the measurement: ceiling_bench.cpp).
#include "ceiling_bench.h"

#include <sstream>
#include <vector>

#include "pinball/core/format.h"

namespace pinball::bench {
namespace {

nlohmann::json player_json(const CeilingPlayerReport& r) {
  return {{"mean_score_per_ball", r.score.mean()},
          {"score_ci95_half_width", r.score.ci95_half_width()},
          {"score_stddev", r.score.stddev()},
          {"mean_ball_time_s", r.duration_s.mean()},
          {"flips_per_ball", r.flips.mean()},
          {"balls_cut_at_time_limit", r.cut},
          {"drains_left_outlane", r.drains.left_outlane},
          {"drains_elsewhere", r.drains.total() - r.drains.left_outlane},
          {"drains_right_outlane", r.drains.right_outlane},
          {"drains_centre", r.drains.centre},
          {"drains_other", r.drains.other},
          {"drains_left_table", r.drains.left_table},
          {"decisions_per_ball", r.decisions_per_ball},
          {"branch_steps_per_ball", r.branch_steps_per_ball},
          {"wall_s", r.wall_s}};
}

}  // namespace

nlohmann::json to_json(const CeilingReport& r) {
  const CeilingBenchOptions& o = r.options;
  const learn::LookaheadConfig& p = o.planner;
  nlohmann::json players = {{"ceiling", player_json(r.ceiling)},
                            {"spastic", player_json(r.spastic)},
                            {"no_flipping", player_json(r.no_flipping)},
                            {"tracker_spastic", player_json(r.tracker_spastic)}};
  if (r.controller) players["controller"] = player_json(*r.controller);
  if (r.controller_true_state) players["controller_true_state"] = player_json(*r.controller_true_state);
  return {{"benchmark", "ceiling"},
          {"board", r.board},
          {"world_board", r.world_board},
          {"world", r.world},
          {"balls", o.balls},
          {"seed", o.seed},
          {"threads", o.threads},
          {"max_ball_time_s", o.max_ball_time_s},
          {"actuation_delay_s", o.actuation_delay_s},
          {"pull", o.pull},
          {"spastic_reach_factor", o.spastic_reach_factor},
          {"planner",
           {{"frame_steps", p.frame_steps},
            {"fire_frames", p.fire_frames},
            {"hold_frames", p.hold_frames},
            {"zone_factor", p.zone_factor},
            {"horizon_s", p.horizon_s},
            {"drain_penalty", p.drain_penalty},
            {"step_budget", p.step_budget}}},
          {"players", players},
          {"controller", o.controller_name},
          {"ceiling_over_spastic", r.ceiling_over_spastic},
          {"ceiling_over_tracker_spastic", r.ceiling_over_tracker_spastic},
          // null when no controller was played (not a ratio of 0)
          {"controller_over_tracker_spastic",
           r.controller ? nlohmann::json(r.controller_over_tracker_spastic) : nlohmann::json(nullptr)},
          {"true_state_feed", o.true_state_feed ? nlohmann::json{{"position_noise_m", o.true_state_feed->position_noise_m},
                                                                 {"velocity_noise_mps", o.true_state_feed->velocity_noise_mps}}
                                                : nlohmann::json(nullptr)},
          {"controller_true_state_over_tracker_spastic",
           r.controller_true_state ? nlohmann::json(r.controller_true_state_over_tracker_spastic)
                                   : nlohmann::json(nullptr)}};
}

std::string to_text(const CeilingReport& r) {
  std::ostringstream out;
  const CeilingBenchOptions& o = r.options;
  out << "ceiling reference on " << r.board << " (world: " << r.world_board << ", "
      << (r.world == "twin" ? std::string("the MuJoCo twin") : "the " + r.world + " stepper") << "): " << o.balls << " balls per player (seed " << o.seed
      << "), cut at " << format_number(o.max_ball_time_s) << " s, actuation delay "
      << format_number(o.actuation_delay_s * 1e3) << " ms\n"
      << "the ceiling player CHEATS (the world's true state, lookahead in the belief's model, which is the "
         "world itself only in the model world): a reference, not a controller\n";
  std::vector<const CeilingPlayerReport*> players = {&r.ceiling, &r.spastic, &r.no_flipping, &r.tracker_spastic};
  if (r.controller) players.push_back(&*r.controller);
  if (r.controller_true_state) players.push_back(&*r.controller_true_state);
  for (const CeilingPlayerReport* p : players) {
    out << "  " << p->name << ": " << format_mean_ci(p->score.mean(), p->score.ci95_half_width())
        << " per ball (95 %), " << format_number(p->duration_s.mean()) << " s per ball, "
        << format_number(p->flips.mean()) << " flips per ball, " << p->cut << " cut; drains: left outlane "
        << p->drains.left_outlane << ", elsewhere " << p->drains.total() - p->drains.left_outlane << " (centre "
        << p->drains.centre << ", right outlane " << p->drains.right_outlane << ", other " << p->drains.other
        << "); wall " << format_number(p->wall_s) << " s\n";
  }
  out << "  ceiling planning: " << format_number(r.ceiling.decisions_per_ball) << " decisions, "
      << format_number(r.ceiling.branch_steps_per_ball) << " lookahead steps per ball\n"
      << "ceiling / spastic: " << format_number(r.ceiling_over_spastic)
      << "x; ceiling / spastic through the tracker: " << format_number(r.ceiling_over_tracker_spastic) << "x\n";
  if (r.controller) {
    out << "controller (" << o.controller_name << ") / spastic through the tracker: "
        << format_number(r.controller_over_tracker_spastic) << "x\n";
  }
  if (r.controller_true_state) {
    out << "controller fed the true state (noise " << format_number(o.true_state_feed->position_noise_m * 1e3)
        << " mm, " << format_number(o.true_state_feed->velocity_noise_mps) << " m/s) / spastic through the tracker: "
        << format_number(r.controller_true_state_over_tracker_spastic) << "x\n";
  }
  return out.str();
}

}  // namespace pinball::bench
