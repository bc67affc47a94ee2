// Trajectories as CSV: whole, or streamed to disk as a run goes.
#pragma once

#include <cstddef>
#include <filesystem>
#include <lcsim/io/atomic_output.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim::io {

// CSV with header t, state (q names then v names for mechanical models, x1..
// or the model's state names otherwise), u1.. (u_<pair>), y1.. (y_<pair>),
// the model's outputs, for models with friction ut_<contact> (the tangential
// multiplier, N), ut2_<contact> (along the second tangent, N; models with
// 3-D friction only) and fm_<contact> (the mode: open, stick, slip+, slip-,
// or for a 3-D contact slip-edge-<i> / slip-face-<i>), mode (active
// constraints joined by ';').
std::string trajectory_csv(const mech::Model& model, const sim::Trajectory& traj);

// The names of the state's entries as the trajectory CSV has them: the
// coordinates then "v_<coordinate>" (mechanical); the model's state names
// (a circuit's "C1.v", "L1.i"), else x1.. (LCS). The one list of them: the
// sensitivity outputs and a study's final-state columns use it too.
std::vector<std::string> state_names(const mech::Model& model);

// The same CSV streamed to disk as a run goes (sim::Options::sample_sink), so
// a long run's output never has to fit in memory: rows go to a temporary
// file beside `path` (".<name>.tmp-XXXXXX"), which commit() renames into
// place; a writer destroyed without commit() (a failed or refused run, an
// exception) removes it. So `path` appears whole or not at all.
// The constructor throws InputError when no file can be created beside
// `path`; write() never throws (a sink must not): a write error is kept and
// thrown by commit() as InputError "<path>: cannot write: <reason>".
// The output columns of an LCS model (mech::Model::output_names): how many,
// and z = x x + u u.
struct CsvOutputs {
  int names = 0;
  Eigen::MatrixXd x, u;
  // A switched circuit's outputs in each configuration (mech::Model::
  // configurations), chosen by sim::Sample::configuration; empty otherwise.
  std::vector<Eigen::MatrixXd> config_x, config_u;
};

class TrajectoryCsvWriter {
 public:
  TrajectoryCsvWriter(const std::filesystem::path& path, const mech::Model& model);
  ~TrajectoryCsvWriter();
  TrajectoryCsvWriter(const TrajectoryCsvWriter&) = delete;
  TrajectoryCsvWriter& operator=(const TrajectoryCsvWriter&) = delete;
  void write(const sim::Sample& sample) noexcept;
  void commit();
  const std::string& temporary_path() const { return temporary_; }

 private:
  void flush() noexcept;
  static constexpr std::size_t kBufferBytes = 1 << 20;
  std::string path_, temporary_, buffer_, logic_error_;
  int n_ = 0, k_ = 0, nf_ = 0, fd_ = -1, error_ = 0;  // nf_: frictional contacts
  bool cone_ = false;  // the model has 3-D friction: the ut2_ columns
  std::size_t rows_ = 0;
  CsvOutputs outputs_;
};

}  // namespace lcsim::io
