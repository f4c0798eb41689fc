#!/usr/bin/env bash
# The house style, checked (scripts/test.sh runs it; docs/extending.md, "House rules"):
#  1. every tracked .cc and .h is exactly what clang-format writes (.clang-format); ~2 s;
#  2. clang-tidy's checks (.clang-tidy) give no warning on the files changed since it last read all.
#   scripts/check-style.sh [BUILD_DIR]    clang-tidy reads BUILD_DIR/compile_commands.json (build/)
# Which files clang-tidy reads: the whole project was last found clean at the commit named in
# .ci/tidy-clean; the .cc files changed since (the mechanical commits listed in
# .git-blame-ignore-revs left out), and the .cc beside each changed header, are read again.
# clang-tidy costs about what compiling does (~8 s a file here, ~40 CPU-minutes for the whole
# project), which CI's hour does not hold every run. SPRITESTATION_TIDY=all reads every .cc (then
# write HEAD's hash into .ci/tidy-clean when it passes), =0 none, =list names the files.
# Both tools are Debian 12's (14): another version formats some lines differently.
set -euo pipefail
top="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$top/build}"
cd "$top"
status=0

mapfile -t sources < <(git ls-files '*.cc' '*.h')
if ! clang-format --dry-run -Werror "${sources[@]}" 2>"$build/check-format.log"; then
  echo "check-style: not formatted as .clang-format says (fix: clang-format -i FILE...):" >&2
  grep -o '^[^:]*:[0-9]*' "$build/check-format.log" | sort -u | head -20 >&2
  status=1
else
  echo "check-style: ${#sources[@]} files formatted"
fi

tidy="${SPRITESTATION_TIDY:-changed}"
if [ "$tidy" = 0 ]; then exit $status; fi
[ -f "$build/compile_commands.json" ] || { echo "check-style: no $build/compile_commands.json (run scripts/build.sh)" >&2; exit 2; }
# With SPRITESTATION_UNITY_BUILD (cmake/Helpers.cmake) the database names the batches
# (<build>/**/unity/*.cc), not the files they include: clang-tidy reads one made from it, with an
# entry for each included file under its batch's command.
db="$build"
if grep -q '/unity/[A-Za-z0-9_]*_[0-9]*\.cc"' "$build/compile_commands.json"; then
  db="$build/tidy-db"
  mkdir -p "$db"
  awk -v top="$top" '
    function emit(src,  c, i) {
      c = command; i = index(c, unity)
      if (i) c = substr(c, 1, i - 1) src substr(c, i + length(unity))
      printf "%s{\n%s\n  \"command\": \"%s\",\n  \"file\": \"%s\"\n}", (n++ ? ",\n" : "[\n"), directory, c, src
    }
    /^  "directory": / { directory = $0; next }
    /^  "command": / { command = $0; sub(/^  "command": "/, "", command); sub(/",$/, "", command); next }
    /^  "file": / {
      unity = $0; sub(/^  "file": "/, "", unity); sub(/",?$/, "", unity)
      if (unity !~ /\/unity\/[A-Za-z0-9_]+_[0-9]+\.cc$/) { emit(unity); next }
      while ((getline line < unity) > 0)
        if (line ~ /^#include "/) { sub(/^#include "/, "", line); sub(/"$/, "", line); emit(top "/" line) }
      close(unity)
    }
    END { print (n ? "\n]" : "[]") }' "$build/compile_commands.json" >"$db/compile_commands.json"
fi
if [ "$tidy" = all ]; then
  mapfile -t changed < <(git ls-files '*.cc')
else
  base="$(grep -oE '^[0-9a-f]{40}' .ci/tidy-clean | head -1)"
  git cat-file -e "$base^{commit}" 2>/dev/null || { echo "check-style: .ci/tidy-clean names no commit of this history" >&2; exit 2; }
  skip=()
  [ -f .git-blame-ignore-revs ] && mapfile -t skip < <(grep -E '^[0-9a-f]{40}$' .git-blame-ignore-revs)
  changed=()
  # Other checks since then: every file again.
  if ! git diff --quiet "$base" HEAD -- .clang-tidy; then mapfile -t changed < <(git ls-files '*.cc'); fi
  for c in $(git rev-list --no-merges "$base..HEAD"); do
    printf '%s\n' "${skip[@]}" | grep -qx "$c" && continue
    mapfile -t -O "${#changed[@]}" changed < <(git diff-tree --no-commit-id --name-only -r "$c")
  done
fi
files=()
for f in $(printf '%s\n' "${changed[@]}" | sed -n 's/\.\(cc\|h\)$/.cc/p' | sort -u); do
  # Only what still exists and is compiled in this build (compile_commands.json names it).
  [ -f "$f" ] && grep -q "\"file\": \"$top/$f\"" "$db/compile_commands.json" && files+=("$f")
done
if [ "$tidy" = list ]; then printf '%s\n' "${files[@]}"; exit $status; fi
if [ ${#files[@]} -eq 0 ]; then
  echo "check-style: clang-tidy: no C++ file changed since .ci/tidy-clean"
  exit $status
fi
log="$build/check-tidy.log"
if ! printf '%s\n' "${files[@]}" | xargs -P "$(nproc)" -n 4 clang-tidy -p "$db" --quiet \
    --warnings-as-errors='*' >"$log" 2>&1; then
  echo "check-style: clang-tidy found (log $log):" >&2
  grep -E 'error:' "$log" | sort -u | head -20 >&2
  status=1
else
  echo "check-style: clang-tidy clean on ${#files[@]} files"
fi
exit $status
