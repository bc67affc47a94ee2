#!/usr/bin/env bash
# lcsim quick start: install what is missing (Debian 12 packages, as root),
# build in Release, then run the main demo (`demo`) or the whole test suite
# (`test`). Nothing is downloaded but Debian packages; nothing is vendored.
set -euo pipefail
cd "$(dirname "$0")/.."

what=${1:-demo}
case "$what" in demo | test) ;; *)
  echo "usage: $0 demo|test" >&2
  exit 2
  ;;
esac

packages=(
  cmake make g++ pkg-config
  libeigen3-dev liburdfdom-dev libbullet-dev libbullet-extras-dev coinor-libipopt-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-matplotlib
  pybind11-dev python3-pybind11 python3-numpy python3-scipy python3-pytest python3-hypothesis
  clang libclang-rt-14-dev clang-format
  libsiconos-kernel-dev libsiconos-numerics-dev python3-siconos
  libopenmpi-dev openmpi-bin
  libmujoco-dev ngspice
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "lcsim: installing missing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

jobs=$(nproc 2>/dev/null || echo 2)
# ccache, when installed, serves the objects of an unchanged source from an
# earlier build (it is not installed here: a fresh machine builds everything).
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DLCSIM_WERROR=ON \
  -DPython3_EXECUTABLE=/usr/bin/python3 "${launcher[@]}"
cmake --build build -j"$jobs"

if [ "$what" = demo ]; then
  # The thesis §3.7 run: two carts and a stop, from e^{-A}(0,-1,-1,0) to T = 3.
  mkdir -p out
  ./build/lcsim simulate robots/two_carts.yaml --dt-out 0.01 --out out/two_carts.csv
  ./build/lcsim simulate robots/two_carts.yaml --json > out/two_carts.json
  /usr/bin/python3 python/lcsim/plot.py trajectory out/two_carts.csv --events out/two_carts.json \
    -o out/two_carts.png --title "Two carts with a stop (thesis §3.7, Figure 3.3)"
  echo "lcsim: wrote out/two_carts.csv, out/two_carts.json and out/two_carts.png"
else
  # 1. The test suite, Release build.
  ctest --test-dir build --output-on-failure -j"$jobs"

  # 2. The package as a user gets it: installed into a temporary prefix, the
  #    examples/ built out of tree against it (find_package(lcsim)) and run,
  #    and a program compiled with pkg-config alone. Any failure fails the run.
  pkg=$(mktemp -d)
  trap 'rm -rf "$pkg"' EXIT
  cmake --install build --prefix "$pkg/prefix" >/dev/null
  # invariant_test uses lcsim::impact only: it is configured with pkg-config
  # seeing no module at all, so Bullet and Ipopt are provably not needed.
  mkdir "$pkg/no-pkgconfig"
  for ex in two_carts impact_rules invariant_test registration; do
    no_pc=()
    [ "$ex" != invariant_test ] || no_pc=(env PKG_CONFIG_LIBDIR="$pkg/no-pkgconfig" PKG_CONFIG_PATH=)
    "${no_pc[@]}" cmake -S "examples/$ex" -B "$pkg/build/$ex" \
      -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$pkg/prefix" >/dev/null
    cmake --build "$pkg/build/$ex" -j"$jobs"
  done
  "$pkg/build/two_carts/two_carts" robots/two_carts.yaml
  "$pkg/build/impact_rules/impact_rules" robots/two_carts_hook.yaml
  ctest --test-dir "$pkg/build/invariant_test" --output-on-failure
  # MuJoCo is installed above, so its component must be there and register.
  "$pkg/build/registration/registered_methods" | tee "$pkg/registered.txt"
  grep -q "^made mujoco$" "$pkg/registered.txt"
  pc_dir=$(dirname "$(find "$pkg/prefix" -name lcsim.pc)")
  # shellcheck disable=SC2046 # pkg-config's output is meant to be split
  g++ -std=c++20 -O1 -o "$pkg/registered_methods_pc" examples/registration/registered_methods.cpp \
    $(PKG_CONFIG_PATH="$pc_dir" pkg-config --cflags --libs lcsim-bullet lcsim-ipopt lcsim-mujoco)
  "$pkg/registered_methods_pc" | tee "$pkg/registered_pc.txt"
  grep -q "^made mujoco$" "$pkg/registered_pc.txt"
  # The Python package as installed: imported by a fresh interpreter outside
  # the source tree, from <prefix>/lib/python3/dist-packages, running a tiny
  # simulation (two carts whose stop is hit at t = 0: one impact, thesis §3.7).
  (cd "$pkg" && PYTHONPATH="$pkg/prefix/lib/python3/dist-packages" /usr/bin/python3 -c '
import sys, numpy as np, lcsim
assert lcsim.__file__.startswith(sys.argv[1]), lcsim.__file__
m = lcsim.Model.mechanical(np.eye(2), np.array([[2.0, -1], [-1, 1]]), np.array([[1.0, 0]]))
run = lcsim.simulate(m, x0=[0, -1, -1, 0], t_end=0.5)
assert run.ok and run.events[0].type == "impact", run.message
print("lcsim: the installed Python package imports and runs:", lcsim.__file__)
' "$pkg/prefix")

  # 3. The suite under AddressSanitizer + UndefinedBehaviorSanitizer, and
  # 4. the libFuzzer targets of fuzz/, from one clang build (`build-san/`,
  #    -O1 with line tables: quicker to build than -O2 -g, and the reports
  #    keep their file:line). The libraries are compiled once, instrumented
  #    for both (ASan + UBSan + libFuzzer's coverage, LCSIM_FUZZ); the test
  #    executables link the sanitizers, the fuzz programs libFuzzer's main.
  #    Two builds (g++ for the tests, clang for the fuzzers) compiled the
  #    libraries and the CLI twice, about half of each build's CPU time (the
  #    clean-clone CI run took 44 min with two). Any report fails the run:
  #    UBSan is built with -fno-sanitize-recover, ASan halts on its first
  #    error.
  #    Built: the test executables of the library layers and of the command
  #    line (its bad-input tests are the sanitizers' best prey); not
  #    test_bullet (Bullet's scenes, checked in step 1; Bullet itself is not
  #    instrumented, and lcsim's Bullet code still runs under ASan through
  #    test_cli's bullet runs) nor test_extremes (stress runs of the
  #    integrators whose code the layer tests cover, again run in step 1):
  #    they are among the heaviest files to instrument (g++ -O1 ASan, CPU s:
  #    test_time_stepping_extremes.cpp 75, test_event_driven_extremes.cpp 65,
  #    test_multibody_world.cpp 45, against 13 to 31 for the layer tests).
  export ASAN_OPTIONS=halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1
  export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
  # Third-party leaks only (urdfdom on cyclic URDFs), each explained there.
  export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
  cmake -S . -B build-san -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DLCSIM_FUZZ=ON \
    -DLCSIM_BUILD_BENCH=OFF -DLCSIM_TESTS="lcp;lcs;mech;impact;sim;io;circuit;scene;app;cli"
  cmake --build build-san -j"$jobs"
  ctest --test-dir build-san --output-on-failure -j"$jobs"

  #    The fuzz targets, each run for LCSIM_FUZZ_SECONDS (default 30) on a
  #    copy of its seed corpus fuzz/corpus/<target>/, side by side. A crash,
  #    a sanitizer report, an escaping exception or a broken invariant fails
  #    the run; the input is kept in build-san/artifacts/.
  targets=()
  for src in fuzz/fuzz_*.cpp; do targets+=("$(basename "$src" .cpp)"); done
  mkdir -p build-san/artifacts
  pids=()
  for t in "${targets[@]}"; do
    rm -rf "build-san/corpus/$t" && mkdir -p "build-san/corpus/$t"
    cp fuzz/corpus/"$t"/* "build-san/corpus/$t/"
    "./build-san/fuzz/$t" "build-san/corpus/$t" -max_total_time="${LCSIM_FUZZ_SECONDS:-30}" \
      -rss_limit_mb=2048 -timeout=20 -max_len=4096 -print_final_stats=1 \
      -artifact_prefix="build-san/artifacts/$t-" >"build-san/$t.log" 2>&1 &
    pids+=($!)
  done
  failed=0
  for i in "${!targets[@]}"; do
    if wait "${pids[$i]}"; then
      echo "lcsim: ${targets[$i]}: $(grep -m1 -o 'stat::number_of_executed_units: *[0-9]*' \
        "build-san/${targets[$i]}.log" | grep -o '[0-9]*$') inputs, no failure"
    else
      failed=1
      echo "lcsim: ${targets[$i]} FAILED; the end of build-san/${targets[$i]}.log:" >&2
      tail -n 60 "build-san/${targets[$i]}.log" >&2
    fi
  done
  exit "$failed"
fi
