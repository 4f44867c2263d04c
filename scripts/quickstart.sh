#!/usr/bin/env bash
# The main job: the demo atlas (atlas/demo.toml: the paper's type (c) ellipsoid over its
# (kappa, energy) plane, 401 x 401 cells, all outputs) with a progress bar, opened in xarray
# and drawn; then the critical set and the paper's Fig. xy trajectory of the same body.
# Installs only what this needs first (bash scripts/setup.sh --quickstart: HDF5, and .venv with
# scripts/requirements-quickstart.txt) and builds only the program, not the Python extension:
# the files are read and drawn by the package's Python source (python/), which needs no
# compiled core for that, unless .venv holds the whole package, current (scripts/test.sh
# installs it). Output: atlas/out/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
start=$SECONDS
bash scripts/setup.sh --quickstart
echo "quickstart: building the program rubber-atlas (cargo build --release --bin rubber-atlas)"
cargo build --release --quiet --bin rubber-atlas
bin=target/release/rubber-atlas
if bash scripts/setup.sh --package-is-current; then
  echo "quickstart: reading and drawing with the package rubber_atlas installed in .venv"
  python=(.venv/bin/python)
else
  echo "quickstart: reading and drawing with the package's Python source (python/, without its compiled core;" \
    "bash scripts/setup.sh installs the whole package)"
  python=(env "PYTHONPATH=$root/python${PYTHONPATH:+:$PYTHONPATH}" .venv/bin/python)
fi
mkdir -p atlas/out
echo "quickstart: rubber-atlas run atlas/demo.toml --out atlas/out/demo.h5 --force"
"$bin" run atlas/demo.toml --out atlas/out/demo.h5 --force
echo "quickstart: opening atlas/out/demo.h5 in xarray"
"${python[@]}" -c "
import rubber_atlas as ra
ds = ra.open_atlas('atlas/out/demo.h5')
print(ds)
"
"${python[@]}" scripts/plot_atlas.py atlas/out/demo.h5 --out atlas/out/demo.png
# The same body (the paper's Figs. php, res and xy): diagram type (c).
alpha=0.5 beta=3 nu=0.5 eta=0.5
echo "quickstart: rubber-atlas diagram --alpha $alpha --beta $beta --nu $nu --eta $eta"
"$bin" diagram --alpha "$alpha" --beta "$beta" --nu "$nu" --eta "$eta" --out atlas/out/paper-c-diagram.h5 --force
echo "quickstart: trajectory of Fig. xy (kappa = 0.8, theta0 = 0.4670288, 7 periods), reduced and full model"
for model in reduced full; do
  "$bin" trajectory --alpha "$alpha" --beta "$beta" --nu "$nu" --eta "$eta" --kappa 0.8 \
    --theta0 0.4670288 --periods 7 --samples 7000 --model "$model" \
    --out "atlas/out/paper-xy-$model.h5" --force
done
"${python[@]}" scripts/plot_trajectory.py atlas/out/paper-xy-reduced.h5 --out atlas/out/paper-xy.png
echo "quickstart: done in $(( (SECONDS - start) / 60 )) min $(( (SECONDS - start) % 60 )) s;" \
  "see atlas/out/ (demo.h5, demo.png, paper-c-diagram.h5, paper-xy-*.h5, paper-xy.png)"
