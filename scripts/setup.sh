#!/usr/bin/env bash
# Installs what rubber-atlas needs and is missing, saying what it does:
#   - Debian's libhdf5-dev and pkg-config (the hdf5 crate links against the system HDF5),
#     and libudunits2-0 (the units library of the CF checker),
#   - a Python virtual environment in .venv with scripts/requirements.txt,
#   - the Python package rubber_atlas (pyproject.toml, built by maturin from this crate)
#     into .venv, again whenever its sources change.
# Sourced by scripts/quickstart.sh and scripts/test.sh; safe to run again.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

need_apt=()
command -v pkg-config >/dev/null 2>&1 || need_apt+=(pkg-config)
if ! pkg-config --exists hdf5 2>/dev/null && [ ! -e /usr/include/hdf5/serial/hdf5.h ]; then
  need_apt+=(libhdf5-dev)
fi
if ! ldconfig -p 2>/dev/null | grep -q libudunits2; then
  need_apt+=(libudunits2-0)
fi
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${need_apt[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${need_apt[@]}" >/dev/null
else
  echo "setup: libhdf5-dev, pkg-config and libudunits2 already installed"
fi

venv="$root/.venv"
stamp="$venv/.requirements.sha"
want="$(sha256sum "$root/scripts/requirements.txt" | cut -d' ' -f1)"
if [ ! -x "$venv/bin/python" ]; then
  echo "setup: creating the Python virtual environment .venv"
  python3 -m venv "$venv"
fi
if [ "$(cat "$stamp" 2>/dev/null || true)" != "$want" ]; then
  echo "setup: installing Python packages from scripts/requirements.txt into .venv"
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$root/scripts/requirements.txt"
  echo "$want" > "$stamp"
else
  echo "setup: Python packages already installed in .venv"
fi

# The package, built from this tree (no build isolation: maturin comes from requirements.txt)
# and installed like any other, so that tests import it from site-packages.
package_stamp="$venv/.package.sha"
# The sources, and the commit and dirty mark that build.rs bakes into git_commit.
package_want="$(cd "$root" && { find Cargo.toml Cargo.lock build.rs pyproject.toml src python/rubber_atlas \
  -type f -not -name '*.pyc' -print0 | sort -z | xargs -0 sha256sum; git rev-parse HEAD 2>/dev/null || true; \
  git status --porcelain --untracked-files=no 2>/dev/null || true; } | sha256sum | cut -d' ' -f1)"
if [ "$(cat "$package_stamp" 2>/dev/null || true)" != "$package_want" ] \
  || ! "$venv/bin/python" -c "import rubber_atlas" >/dev/null 2>&1; then
  echo "setup: building and installing the Python package rubber_atlas into .venv (maturin, release)"
  PATH="$venv/bin:$PATH" "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    --no-build-isolation --no-deps --force-reinstall "$root"
  echo "$package_want" > "$package_stamp"
else
  echo "setup: the Python package rubber_atlas is installed and current"
fi
