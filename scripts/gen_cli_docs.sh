#!/usr/bin/env bash
# docs/cli.md is generated from the CLI11 definitions (`fiblet help --markdown`).
#   scripts/gen_cli_docs.sh                   build the CLI, rewrite docs/cli.md
#   scripts/gen_cli_docs.sh --check [FIBLET]  exit 1 (with a diff) if docs/cli.md is out of date
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${FIBLET_BUILD_DIR:-$root/build}"
doc="$root/docs/cli.md"
if [ "${1:-}" = "--check" ]; then
  fiblet="${2:-$build/bin/fiblet}"
  generated="$(mktemp)"
  trap 'rm -f "$generated"' EXIT
  "$fiblet" help --markdown >"$generated"
  if ! diff -u "$doc" "$generated"; then
    echo "docs/cli.md is out of date: run scripts/gen_cli_docs.sh" >&2
    exit 1
  fi
  echo "docs/cli.md is up to date"
  exit 0
fi
[ -d "$build" ] || cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target fiblet_cli >/dev/null
mkdir -p "$root/docs"
"$build/bin/fiblet" help --markdown >"$doc.tmp"
mv "$doc.tmp" "$doc"
echo "wrote $doc"
