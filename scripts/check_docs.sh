#!/usr/bin/env bash
# The repository documents itself (run by ctest as Docs.SelfContained):
#  - no text in it reads as a work log or points outside the repository: none of the words
#    below in README.md, CHANGELOG.md, docs/, src/, tests/, bench/ (but its measured results),
#    scripts/, cases/, cuda/, fuzz/, CMakeLists.txt and .ci/ (this file included);
#  - README.md is a front page of at most 200 lines whose "Quick start" is one fenced block of
#    exactly two commands;
#  - every docs/*.md page the README names exists.
set -uo pipefail
cd "$(dirname "$0")/.."
status=0
fail() { printf 'check_docs: %s\n' "$*" >&2; status=1; }

# The words of a work log (its dated stages, numbered tasks and notes) and paths outside the
# repository, case-insensitive. Each word is written with one letter in brackets, so that this
# file, checked like every other, does not match its own pattern.
pattern='s[e]ssion|this p[a]ss|(i[s]sue|i[t]em|s[t]age) #?[0-9]|the i[s]sue|lab n[o]tes|\.\./s[h]ared|D[E]SIGN\.md'
hits=$(grep -rnIiE "$pattern" README.md CHANGELOG.md docs src tests bench scripts cases cuda fuzz \
  CMakeLists.txt .ci --exclude-dir=results 2>/dev/null)
[ -z "$hits" ] || fail "work-log words or paths outside the repository:"$'\n'"$hits"

lines=$(wc -l <README.md)
[ "$lines" -le 200 ] || fail "README.md has $lines lines (at most 200)"

# The Quick start block: the first fenced block after the heading, two non-empty lines.
commands=$(awk '/^## Quick start/{q=1; next} q && /^```/{if (f) exit; f=1; next} q && f && NF' README.md)
count=$(printf '%s\n' "$commands" | grep -c .)
[ "$count" -eq 2 ] || fail "README.md's Quick start block has $count commands (exactly 2)"
printf '%s\n' "$commands" | head -1 | grep -q 'cases/perforation.toml' ||
  fail "the first Quick start command does not run the main job (cases/perforation.toml)"
printf '%s\n' "$commands" | tail -1 | grep -q 'ctest' ||
  fail "the second Quick start command does not run the test suite (ctest)"

for page in $(grep -oE 'docs/[a-z_-]+\.md' README.md | sort -u); do
  [ -f "$page" ] || fail "README.md links $page, which does not exist"
done
exit $status
