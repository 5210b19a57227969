#!/usr/bin/env bash
# Fails (and names each file) when clang-format, with the repository's
# .clang-format, would change any tracked C++ file. Apply with scripts/format.
set -euo pipefail
root="${1:?usage: check_format.sh REPO_ROOT}"
cd "$root"
if ! command -v clang-format >/dev/null; then
  echo "check_format: clang-format not found (package clang-format; scripts/install-deps installs it)"
  exit 1
fi
mapfile -t files < <(git ls-files --cached --others --exclude-standard '*.cpp' '*.hpp' '*.h' '*.cc')
bad=()
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    bad+=("$f")
  fi
done
if [ ${#bad[@]} -ne 0 ]; then
  printf 'check_format: not formatted (run scripts/format): %s\n' "${bad[@]}"
  exit 1
fi
echo "check_format: PASS (${#files[@]} files formatted)"
