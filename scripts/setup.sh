#!/usr/bin/env bash
# Installs what rubber-atlas needs and is missing, saying what it does. Safe to run again.
#
#   bash scripts/setup.sh               everything (scripts/test.sh runs this):
#     - Debian's libhdf5-dev and pkg-config (the hdf5 crate links against the system HDF5),
#       and libudunits2-0 (the units library of the CF checker),
#     - a Python virtual environment in .venv with scripts/requirements.txt,
#     - the Python package rubber_atlas (pyproject.toml, built by maturin from this crate)
#       into .venv, again whenever its sources change.
#   bash scripts/setup.sh --quickstart  what the quick start needs (scripts/quickstart.sh):
#     - libhdf5-dev and pkg-config,
#     - .venv with scripts/requirements-quickstart.txt only (reading and drawing files),
#     - not the package: the quick start reads and draws with its Python source (python/).
#   bash scripts/setup.sh --without-package   everything but the package;
#   bash scripts/setup.sh --package-only      the package alone, into the .venv set up before
#     (scripts/test.sh builds it beside the Rust tests' build, which leaves a core idle).
#   bash scripts/setup.sh --package-is-current
#     installs nothing; exits 0 when .venv holds the package built from this tree as it is.
#
# The stamps in .venv record what was installed: .requirements.sha the full set (only the
# full set-up writes it), .requirements-quickstart.sha the quick start's, .package.sha the
# package's sources. A quick start's .venv is completed by the next full set-up.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

mode=full
package=yes
case "${1:-}" in
  "") ;;
  --without-package) package=no ;;
  --package-only) package=only ;;
  --quickstart) mode=quickstart ;;
  --package-is-current) mode=package-is-current ;;
  -h | --help) sed -n '2,22p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "setup: unknown option $1 (--quickstart, --without-package, --package-only, --package-is-current, or none for everything)" >&2; exit 2 ;;
esac

venv="$root/.venv"
package_stamp="$venv/.package.sha"

# The package's sources, and the commit and dirty mark that build.rs bakes into git_commit.
package_want() {
  (cd "$root" && { find Cargo.toml Cargo.lock build.rs pyproject.toml src python/rubber_atlas \
    -type f -not -name '*.pyc' -print0 | sort -z | xargs -0 sha256sum; git rev-parse HEAD 2>/dev/null || true; \
    git status --porcelain --untracked-files=no 2>/dev/null || true; } | sha256sum | cut -d' ' -f1)
}

# Whether .venv holds the package (its compiled core) built from the sources as they are.
package_is_current() {
  [ "$(cat "$package_stamp" 2>/dev/null || true)" = "$(package_want)" ] \
    && [ -x "$venv/bin/python" ] \
    && (cd "$venv" && env -u PYTHONPATH "$venv/bin/python" -c "import rubber_atlas._core" >/dev/null 2>&1)
}

# The package, built from this tree (no build isolation: maturin comes from requirements.txt)
# and installed like any other, so that tests import it from site-packages. Built in a target
# folder of its own (target/python-package), so that it can build while cargo builds in target/.
build_package() {
  if ! package_is_current; then
    local want
    want="$(package_want)"  # before the build: an edit during it leaves the package stale
    echo "setup: building and installing the Python package rubber_atlas into .venv (maturin, release)"
    CARGO_TARGET_DIR="$root/target/python-package" PATH="$venv/bin:$PATH" "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
      --no-build-isolation --no-deps --force-reinstall "$root"
    echo "$want" > "$package_stamp"
  else
    echo "setup: the Python package rubber_atlas is installed and current"
  fi
}

if [ "$mode" = package-is-current ]; then
  package_is_current
  exit
fi

if [ "$package" = only ]; then
  build_package
  exit
fi

need_apt=()
command -v pkg-config >/dev/null 2>&1 || need_apt+=(pkg-config)
if ! pkg-config --exists hdf5 2>/dev/null && [ ! -e /usr/include/hdf5/serial/hdf5.h ]; then
  need_apt+=(libhdf5-dev)
fi
if [ "$mode" = full ] && ! ldconfig -p 2>/dev/null | grep -q libudunits2; then
  need_apt+=(libudunits2-0)
fi
if [ ${#need_apt[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${need_apt[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq "${need_apt[@]}" >/dev/null
elif [ "$mode" = full ]; then
  echo "setup: libhdf5-dev, pkg-config and libudunits2 already installed"
else
  echo "setup: libhdf5-dev and pkg-config already installed"
fi

if [ ! -x "$venv/bin/python" ]; then
  echo "setup: creating the Python virtual environment .venv"
  python3 -m venv "$venv"
fi

# The full list includes the quick start's (requirements.txt reads requirements-quickstart.txt):
# its stamp covers both files, and satisfies the quick start too.
full_stamp="$venv/.requirements.sha"
full_want="$(cat "$root/scripts/requirements-quickstart.txt" "$root/scripts/requirements.txt" | sha256sum | cut -d' ' -f1)"
quick_stamp="$venv/.requirements-quickstart.sha"
quick_want="$(sha256sum "$root/scripts/requirements-quickstart.txt" | cut -d' ' -f1)"
full_installed=false
[ "$(cat "$full_stamp" 2>/dev/null || true)" = "$full_want" ] && full_installed=true
if [ "$mode" = full ]; then
  if ! $full_installed; then
    echo "setup: installing Python packages from scripts/requirements.txt into .venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$root/scripts/requirements.txt"
    echo "$full_want" > "$full_stamp"
  else
    echo "setup: Python packages already installed in .venv"
  fi
else
  if ! $full_installed && [ "$(cat "$quick_stamp" 2>/dev/null || true)" != "$quick_want" ]; then
    echo "setup: installing the quick start's Python packages (scripts/requirements-quickstart.txt) into .venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$root/scripts/requirements-quickstart.txt"
    echo "$quick_want" > "$quick_stamp"
  else
    echo "setup: the quick start's Python packages already installed in .venv"
  fi
  exit 0
fi

if [ "$package" = yes ]; then
  build_package
fi
