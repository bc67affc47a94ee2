// Studies: a study file's axes expanded into runs (docs/study.md).
//
// Public face of src/study (above io and bullet, below cli). A study names a
// model (or several), axes of values and the quantities they set; run i is
// one point of the Cartesian product of the axes, the first axis varying
// slowest. Everything here is a pure function of the study file, so any
// process (a thread, an MPI rank, a resumed run) computes the same run i.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim::study {

// What an axis sets. The key as the study file spells it:
//   model            index into Study::models (the `models:` list)
//   method, impact   names (sim::integrators(), impact::impact_laws())
//   h, theta, t_end  sim::Options
//   x0.<coord>       initial position of a coordinate (m or rad)
//   v0.<coord>       initial velocity of a coordinate
//   restitution.<constraint>
//   mu.<constraint>  the friction coefficient of its mechanical.friction entry
//   scale.<M|D|K>    the whole matrix times the value
//   scale.<M|D|K>.<coord>.<coord>   one entry, and its mirror (symmetry kept)
//   scale.<f>.<coord>, scale.g.<constraint>   one entry of f or g
struct Quantity {
  enum class Kind {
    kModel,
    kMethod,
    kImpact,
    kH,
    kTheta,
    kTEnd,
    kX0,
    kV0,
    kRestitution,
    kMu,
    kScale
  };
  Kind kind = Kind::kH;
  std::string key;     // as written ("x0.x1", "scale.K")
  std::string matrix;  // kScale: "M", "D", "K", "f" or "g"
  int row = -1;        // kX0, kV0, kRestitution, kMu, kScale entries: 0-based index; -1 = whole
  int col = -1;        // kScale of M, D, K entries
  bool text() const { return kind == Kind::kMethod || kind == Kind::kImpact; }
};

// One value of an axis: a name (method, impact) or a number.
struct Value {
  std::string name;
  double number = 0.0;
};

// An axis: several quantities that vary together (a "zip"), each with
// `count` values. Random draws are made when the run is expanded (draw).
struct Distribution {
  enum class Kind { kNone, kUniform, kNormal, kLogUniform };
  Kind kind = Kind::kNone;
  double a = 0.0, b = 0.0;  // [low, high] or (mean, standard deviation)
};
struct Axis {
  std::vector<Quantity> quantities;
  // Per quantity: its `count` values, or (random) its distribution.
  std::vector<std::vector<Value>> values;
  std::vector<Distribution> random;
  std::size_t count = 0;
};

struct Study {
  std::string source;  // the study file's path, for messages
  std::string name;
  std::vector<mech::Model> models;  // one, or the `models:` list (axis `model`)
  std::vector<std::string> model_paths;
  std::vector<Axis> axes;
  sim::Options base;  // t_end (unset: the model's), method defaults below
  std::string method = "event";
  std::uint64_t seed = 0;
  std::string reference = "event";  // "event" (the exact method) or "none"
  std::string fingerprint;          // hash of the file's text: a journal belongs to one study
};

// Reads and checks a study file: InputError "<file>: <key>: <what> (got
// <value>)" for anything wrong (unknown key, quantity, coordinate, method or
// law, an empty axis, axes of a zip of different lengths, bad ranges). The
// model paths are relative to the study file's directory.
Study load_study(const std::filesystem::path& path);
Study parse_study(const std::string& yaml_text, const std::string& source);

// Number of runs: the product of the axes' counts (1 with no axis).
std::size_t run_count(const Study& s);

// The value each quantity takes in run `index` (< run_count), flattened in
// axis order, and the index of the run on each axis.
struct RunPoint {
  std::size_t index = 0;
  std::vector<std::size_t> axis_index;  // per axis
  std::vector<Value> values;            // per quantity, axes in order
};
RunPoint expand(const Study& s, std::size_t index);

// The keys of the flattened quantities ("method", "x0.x1", ...).
std::vector<std::string> quantity_keys(const Study& s);

// ---- Random draws, independent of scheduling ----
// SplitMix64 (Steele, Lea, Flood 2014): advances `state` by the golden gamma
// 0x9e3779b97f4a7c15 and returns the mixed value.
std::uint64_t splitmix64(std::uint64_t& state);
// The seed of draw `draw` of quantity `quantity` of axis `axis`:
// state = seed; then for each of axis, quantity, draw: state = splitmix64(state) ^ that,
// and a last splitmix64. A pure function of the study seed and the run's
// point on the axis, so every process draws the same numbers.
std::uint64_t draw_seed(std::uint64_t seed, std::size_t axis, std::size_t quantity,
                        std::size_t draw);
// A uniform double in [0, 1): the top 53 bits of splitmix64 times 2^-53.
double uniform01(std::uint64_t& state);
// One draw of `d` from the generator state (normal: Box-Muller on two
// uniforms, u1 in (0, 1]: mean + sd sqrt(-2 ln u1) cos(2 pi u2)).
double draw(const Distribution& d, std::uint64_t& state);

// linspace: count values from a to b, a + i (b - a) / (count - 1), the last
// exactly b; logspace: exp of the linspace of ln a, ln b, ends exactly a and b.
std::vector<double> linspace(double a, double b, std::size_t count);
std::vector<double> logspace(double a, double b, std::size_t count);

}  // namespace lcsim::study
