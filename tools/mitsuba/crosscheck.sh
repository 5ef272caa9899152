#!/usr/bin/env bash
# Cross-check ref-tracer against Mitsuba 3: makes a Python environment with Mitsuba in
# target/mitsuba-venv (PyPI), finds a libLLVM >= 17 for Dr.Jit's LLVM backend (installs
# Debian's libllvm19 when missing and apt is usable), then runs crosscheck.py with the arguments
# given, e.g. tools/mitsuba/crosscheck.sh --envmap ../shared/envmaps/venice_sunset_1k.hdr
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/mitsuba-venv
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import mitsuba, numpy" 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet mitsuba numpy
fi
find_llvm() {
  ls /usr/lib/x86_64-linux-gnu/libLLVM.so.{22,21,20,19,18,17}* /usr/lib/x86_64-linux-gnu/libLLVM-{22,21,20,19,18,17}.so 2>/dev/null | head -1
}
llvm=${DRJIT_LIBLLVM_PATH:-$(find_llvm || true)}
if [ -z "$llvm" ]; then
  # a fresh machine's package lists may be empty or old: update them first
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt-get update -qq && apt-get install -y -q libllvm19 >/dev/null
  elif command -v apt-get >/dev/null; then
    sudo apt-get update -qq && sudo apt-get install -y -q libllvm19 >/dev/null
  fi
  llvm=$(find_llvm || true)
fi
[ -n "$llvm" ] || { echo "no libLLVM >= 17 found (Dr.Jit's LLVM backend needs one); set DRJIT_LIBLLVM_PATH" >&2; exit 1; }
export DRJIT_LIBLLVM_PATH=$llvm
exec "$venv/bin/python" tools/mitsuba/crosscheck.py "$@"
