#!/usr/bin/env bash
# Every test of rubber-atlas: formatting and lints, the Rust tests (release mode: the numerical
# tests integrate the equations of motion), the Python tests of scripts/ and those of the
# installed package (python/tests). Installs what is missing first (scripts/setup.sh). Exits non-zero if any suite fails or runs no test.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
start=$SECONDS
# Names the next phase, after the time since the start (the phases' times for a slow run).
phase() {
  echo "test: [$(( SECONDS - start )) s] $1"
}
bash scripts/setup.sh --without-package
# The Python package builds beside the Rust checks and tests, whose builds leave a core idle
# part of the time; its output is shown when it is waited for.
package_log="$(mktemp)"
outside="$(mktemp -d)"
bash scripts/setup.sh --package-only > "$package_log" 2>&1 &
package_pid=$!
trap 'kill "$package_pid" 2>/dev/null || true; rm -rf "$outside" "$package_log"' EXIT
phase "cargo fmt --check"
cargo fmt --all -- --check
phase "cargo clippy -D warnings (the program, and the Python extension's features)"
cargo clippy --release --all-targets --quiet -- -D warnings
cargo clippy --release --lib --no-default-features --features python --quiet -- -D warnings
phase "cargo test --release"
cargo test --release
phase "waiting for the Python package (bash scripts/setup.sh --package-only)"
if ! wait "$package_pid"; then
  cat "$package_log"
  echo "test: building the Python package failed" >&2
  exit 1
fi
cat "$package_log"
# The program cargo test built (with the dev-dependencies' features; a plain cargo build
# would compile it again for nothing). The two Python suites run side by side: each keeps
# about one core busy (measured: 85 s of CPU in 81 s for python/tests). The package's suite
# is shown when it ends; either failing fails the command.
phase "pytest python/tests (on the installed package, from a folder outside the repository) beside pytest scripts/tests"
python_log="$(mktemp)"
(cd "$outside" && RUBBER_ATLAS_BIN="$root/target/release/rubber-atlas" \
  "$root/.venv/bin/python" -m pytest -q -p no:cacheprovider --rootdir "$outside" "$root/python/tests") \
  > "$python_log" 2>&1 &
python_pid=$!
trap 'kill "$package_pid" "$python_pid" 2>/dev/null || true; rm -rf "$outside" "$package_log" "$python_log"' EXIT
scripts_status=0
RUBBER_ATLAS_BIN="$root/target/release/rubber-atlas" .venv/bin/python -m pytest -q --durations=10 scripts/tests \
  || scripts_status=$?
phase "scripts/tests ended; waiting for python/tests"
python_status=0
wait "$python_pid" || python_status=$?
echo "test: pytest python/tests:"
cat "$python_log"
if [ "$scripts_status" -ne 0 ] || [ "$python_status" -ne 0 ]; then
  echo "test: a Python suite failed (scripts/tests exit $scripts_status, python/tests exit $python_status)" >&2
  exit 1
fi
echo "test: all suites passed in $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s"
