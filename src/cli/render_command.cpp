// `pinball render BOARD --out FILE.png`: draws a board file.

#include <filesystem>
#include <ostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "data_file.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/png_file.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/renderer.h"
#include "pinball/table/board_loader.h"

namespace pinball::cli {

CLI::App* add_render_command(CLI::App& app, RenderArgs& a) {
  CLI::App* cmd = app.add_subcommand("render", "draw a board file to a PNG");
  cmd->add_option("board", a.board, "board file")->required()->transform(data_file());
  cmd->add_option("--out", a.out, "PNG file to write")->required()->check(output_file());
  cmd->add_option("--px-per-m", a.px_per_m, "scale in pixels per metre")->check(finite_range(50.0, 10000.0));
  cmd->add_flag("--normals", a.normals, "draw the normal of every line");
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  return cmd;
}

int run_render(const RenderArgs& a, std::ostream& out, std::ostream&) {
  check_png_output(a.out, "--out");
  check_outputs_replace_no_input({{"--out", a.out}}, {{"board", a.board}});  // a board named x.png became a picture
  const table::Board board = table::load_board(a.board);
  sim::RenderOptions options;
  options.px_per_m = a.px_per_m;
  options.draw_normals = a.normals;
  options.draw_hud = false;
  options.draw_scale_bar = true;
  const sim::GameState state = sim::make_game_state(board, 0);
  const std::vector<std::string> notes{
      "x right, y up the table; a lighter shade: the obstacle scores; scale bar at the bottom left"};
  const std::string title = "Board " + std::filesystem::path(a.board).filename().string() + " - pinball render";
  const cv::Mat image =
      plot::annotated_picture(sim::render_board(board, &state, options), sim::board_legend(), title, notes);
  plot::write_png(image, a.out);
  if (a.json) {
    out << json_text(nlohmann::json{{"board", a.board},          {"out", a.out},
                                    {"width_px", image.cols},     {"height_px", image.rows},
                                    {"obstacles", board.obstacles.size()}, {"sensors", board.sensors.size()},
                                    {"flippers", board.flippers.size()}},
                     2)
        << "\n";
  } else {
    out << "wrote " << a.out << " (" << image.cols << "x" << image.rows << " px, " << board.obstacles.size()
        << " obstacle shapes, " << board.sensors.size() << " sensors, " << board.flippers.size() << " flippers)\n";
  }
  return 0;
}

}  // namespace pinball::cli
