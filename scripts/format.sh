#!/usr/bin/env bash
# Formats (default) or checks (--check) every C, C++ and OpenCL source of the repository
# with the committed .clang-format (Debian 12's clang-format 14).
# --check prints the files that differ and exits 1 if there are any.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.cpp' '*.h' '*.inc' '*.cl')
if [ "${1:-}" = "--check" ]; then
  bad=()
  for f in "${files[@]}"; do
    clang-format --style=file "$f" | cmp -s - "$f" || bad+=("$f")
  done
  if [ ${#bad[@]} -gt 0 ]; then
    echo "format: ${#bad[@]} file(s) differ from .clang-format:" >&2
    printf '  %s\n' "${bad[@]}" >&2
    echo "Fix with: scripts/format.sh" >&2
    exit 1
  fi
  echo "format: all ${#files[@]} sources follow .clang-format"
else
  clang-format --style=file -i "${files[@]}"
fi
