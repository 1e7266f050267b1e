#!/bin/sh
# Compiles a source that must fail and checks that the compiler's output holds
# every text the source names in its "// expect: TEXT" lines.
# usage: compile_fail_test.sh CXX SOURCE INCLUDE_DIR...
set -u
compiler=$1 source=$2
shift 2
includes=""
for dir in "$@"; do includes="$includes -I$dir"; done
# shellcheck disable=SC2086 # one -I per folder
if output=$("$compiler" -std=c++20 -fsyntax-only $includes "$source" 2>&1); then
  echo "compiled, but must not: $source"
  exit 1
fi
expectations=$(sed -n 's|^// expect: ||p' "$source")
[ -n "$expectations" ] || { echo "no '// expect:' line in $source"; exit 1; }
echo "$expectations" | while IFS= read -r expected; do
  if ! printf '%s' "$output" | grep -qF -- "$expected"; then
    printf 'the error does not say "%s":\n%s\n' "$expected" "$output"
    exit 1
  fi
done || exit 1
echo "refused as expected: $source"
