#!/usr/bin/env bash
# Every C++ source of the project is formatted as .clang-format says
# (clang-format --dry-run -Werror): the formatting is checked by CI, so a
# change is formatted before it lands (`clang-format -i FILE`).
# Usage: check_format.sh SOURCE_DIR [CLANG_FORMAT]
set -euo pipefail
cd "$1"
cf=${2:-clang-format}
mapfile -t files < <(find src include python/src tests bench examples fuzz \
  -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) | sort)
if "$cf" --dry-run -Werror "${files[@]}"; then
  echo "check_format: ${#files[@]} files formatted as .clang-format says ($("$cf" --version))"
else
  echo "check_format: the files above are not formatted; run clang-format -i on them" >&2
  exit 1
fi
