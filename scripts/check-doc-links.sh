#!/usr/bin/env bash
# Every file the README and docs/ name (bench/results/..., docs/..., scripts/..., relative Markdown links)
# must exist: a quoted result that was moved or removed fails here.
set -euo pipefail
cd "$(dirname "$0")/.."
missing=0
check() { # FILE-THAT-QUOTES PATH
  if [ ! -e "$2" ]; then echo "check-doc-links: $1 names $2, which does not exist" >&2; missing=1; fi
}
for doc in README.md docs/*.md docs/*/README.md; do
  dir=$(dirname "$doc")
  # Paths in backticks or links that start at the repository root.
  while read -r path; do
    check "$doc" "$path"
  done < <(grep -oE '(bench/results|docs|scripts)/[A-Za-z0-9_./-]+\.[a-z]+' "$doc" | sort -u)
  # Result files named relative to bench/results (e.g. `nvidia-h200/batch1g.md`).
  while read -r path; do
    check "$doc" "bench/results/$path"
  done < <(grep -oE '`(nvidia|cpu)-[a-z0-9-]+/[A-Za-z0-9_.-]+\.[a-z]+`' "$doc" | tr -d '`' | sort -u)
  # Relative Markdown links and images.
  while read -r link; do
    case $link in http*|\#*) continue ;; esac
    check "$doc" "$dir/${link%%#*}"
  done < <(grep -oE '\]\([^)]+\)' "$doc" | sed -E 's/^\]\(//; s/\)$//' | sort -u)
done
[ $missing -eq 0 ] && echo "check-doc-links: every file the docs name exists"
exit $missing
