// `lcsim analyze MODEL [--json] [--full]`: what a model is and whether the
// theory applies to it, before simulating (app::analysis_report, which says
// what the report holds). The command parses its flags, prints the report as
// JSON or text, and writes the linear model when asked (--model-out).
#include <iostream>
#include <lcsim/app/analysis.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <string>

#include "cli/command.hpp"
#include "cli/flag_names.hpp"
#include "cli/output.hpp"

namespace lcsim::cli {
namespace {

struct AnalyzeArgs {
  std::string file;
  bool json = false;
  std::string model_out;         // --model-out: the linear model as YAML
  app::AnalysisOptions options;  // --full, --linearisation-threshold
};

void run_analyze(const AnalyzeArgs& args) {
  try {  // before the model is read, as the flags are
    app::check_analysis_options(args.options);
  } catch (const io::InputError& e) {
    throw io::InputError(with_flag_names(e.what(), analyze_flags()));
  }
  if (!args.model_out.empty()) check_writable(args.model_out);
  const scene::LoadedModel loaded = scene::load_model_and_scene(args.file);
  const app::AnalysisReport report = app::analysis_report(loaded, args.options);
  std::string text = with_flag_names(report.text, analyze_flags());
  if (!args.model_out.empty()) {
    const mech::Model& model = loaded.model;
    io::write_file_atomic(args.model_out,
                          io::model_yaml(model, "The linear model of " + model.source +
                                                    ", written by lcsim analyze --model-out"));
    text += "model written to " + args.model_out + "\n";
  }
  if (args.json)
    std::cout << report.json.dump(2) << "\n";
  else
    std::cout << text;
}

}  // namespace

LCSIM_REGISTER_COMMAND([](CLI::App& app) {
  auto args = std::make_shared<AnalyzeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "analyze", "Describe a model and check the well-posedness conditions before simulating");
  cmd->add_option("model", args->file, "model file (YAML)")->required();
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->add_flag("--full", args->options.full,
                "print every matrix and set (default: a summary, which names what it leaves out)");
  cmd->add_option("--model-out", args->model_out,
                  "write the model (a scene: its linearisation) as a YAML model file");
  cmd->add_option("--linearisation-threshold", args->options.linearisation_threshold,
                  "scenes: relative error of the linear model for the ranges (default 0.01)");
  cmd->callback([args] { run_analyze(*args); });
});

}  // namespace lcsim::cli
