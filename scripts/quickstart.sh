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
  libsiconos-kernel-dev libsiconos-numerics-dev python3-siconos
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
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DLCSIM_WERROR=ON
cmake --build build -j"$jobs"

if [ "$what" = demo ]; then
  # The thesis §3.7 run: two carts and a stop, from e^{-A}(0,-1,-1,0) to T = 3.
  mkdir -p out
  ./build/lcsim simulate robots/two_carts.yaml --dt-out 0.01 --out out/two_carts.csv
  ./build/lcsim simulate robots/two_carts.yaml --json > out/two_carts.json
  /usr/bin/python3 bench/plot_trajectory.py out/two_carts.csv --events out/two_carts.json \
    -o out/two_carts.png --title "Two carts with a stop (thesis §3.7, Figure 3.3)"
  echo "lcsim: wrote out/two_carts.csv, out/two_carts.json and out/two_carts.png"
else
  ctest --test-dir build --output-on-failure -j"$jobs"
fi
