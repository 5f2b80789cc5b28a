#!/usr/bin/env bash
# CI for the Python package (crates/batten-py): lint its Rust, build and install it with pip in
# a fresh virtual environment (maturin from PyPI, as a user would), and run its pytest suite,
# the Dask tests on a LocalCluster of 2 worker processes and the bit-for-bit parity with the
# CLI included. Called by .ci/run; runs on its own too.
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
start=$(date +%s)
last=$start
# Seconds since the previous step and since the start, for CI's time budget.
took() { local now; now=$(date +%s); echo "   ($1: $((now - last)) s, $((now - start)) s in all)"; last=$now; }

echo "== python: interpreter, venv and headers"
# A CPython that can make a venv (ensurepip) and build an extension (Python.h): the machine's
# python3, else Debian's, installed here when missing (a python3 first on PATH that lacks them,
# a pyenv build say, is passed over for /usr/bin/python3).
usable() {
  command -v "$1" >/dev/null 2>&1 &&
    "$1" -c 'import ensurepip, venv, os, sys, sysconfig
sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))'
}
python=python3
if ! usable "$python"; then
  python=/usr/bin/python3
  if ! usable "$python"; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
      python3 python3-venv python3-dev python3-pip
  fi
fi
"$python" --version

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$python" -m venv "$work/venv"
py="$work/venv/bin/python"
"$py" -m pip install --quiet --upgrade pip
"$py" -m pip install --quiet "maturin>=1.9,<2" numpy pytest "dask[bag,dataframe,distributed]" pandas
took "venv and PyPI packages"

echo "== batten-py: cargo fmt --check, clippy -D warnings (outside the workspace)"
cargo fmt --manifest-path crates/batten-py/Cargo.toml -- --check
PYO3_PYTHON="$py" cargo clippy --manifest-path crates/batten-py/Cargo.toml --all-targets -- -D warnings
took "fmt and clippy"

echo "== pip install ./crates/batten-py (maturin builds the extension)"
"$py" -m pip install --quiet ./crates/batten-py
"$py" -c 'import batten; print("batten", batten.__version__, "from", batten.__file__)'
took "pip install (maturin, release build)"

echo "== pytest crates/batten-py/tests (against the CLI for parity)"
cargo build --release -p batten-cli
took "the CLI, release (already built by .ci/run)"
# From a directory outside the source tree: the tests import the installed package.
(cd "$work" && BATTEN_CLI="$OLDPWD/target/release/batten" "$py" -m pytest \
  "$OLDPWD/crates/batten-py/tests" -p no:cacheprovider -rs --junitxml "$work/junit.xml")
# pytest fails on a failed test and exits 5 when it collects none (set -e stops on both);
# also refuse a run where tests were skipped (a missing optional dependency).
"$py" - "$work/junit.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
suite = root if root.tag == "testsuite" else root.find("testsuite")
tests, skipped = int(suite.get("tests")), int(suite.get("skipped"))
bad = int(suite.get("failures")) + int(suite.get("errors"))
print(f"pytest: {tests} tests, {skipped} skipped, {bad} failed")
sys.exit(0 if tests >= 50 and skipped == 0 and bad == 0 else 1)
PY
took "pytest"
echo "python: ok in $(($(date +%s) - start)) s"
