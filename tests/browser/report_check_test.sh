#!/usr/bin/env bash
# ctest `browser_report`: `handlabel compare` on a small synthetic capture (capsule hand,
# 3 frames at 160x120; no weights, so the fitting rows run and the network rows say
# why), then tools/browser/check-report.mjs opens report.html in headless
# Debian Chromium: numbers equal compare.json, every image loads, no console errors, a
# screenshot; and it checks itself on broken copies (--self-test).
# Skips (exit 77) only when /usr/bin/chromium or the npm packages are missing
# (`bash scripts/install-browser-deps` installs both).
# Usage: report_check_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$(realpath "$1")
build=$(realpath "$2")
chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ] || ! command -v node > /dev/null; then
  echo "browser_report: SKIP: no $chromium or node (run: bash scripts/install-browser-deps)"
  exit 77
fi
if [ ! -d "$src/tools/browser/node_modules/playwright-core" ]; then
  echo "browser_report: SKIP: tools/browser/node_modules missing (run: bash scripts/install-browser-deps)"
  exit 77
fi
tmp=$(mktemp -d /tmp/handlabel-browser.XXXXXX)
trap '[ -n "${KEEP_TMP:-}" ] || rm -rf "$tmp"' EXIT
hl=$build/apps/handlabel
"$hl" synth --out "$tmp/capture" --preset dexycb --frames 3 --seed 5 --size 160x120 \
  --hand-model capsule > "$tmp/synth.log"
"$hl" compare --capture "$tmp/capture" --hand-model capsule --out "$tmp/compare" \
  --threads 2 --ablation-views 3 --ablation-frames 2 --quiet > "$tmp/compare.log"
node "$src/tools/browser/check-report.mjs" "$tmp/compare/report.html" \
  "$tmp/compare/compare.json" --screenshot "$build/browser_report.png" --self-test
echo "browser_report: screenshot $build/browser_report.png"
