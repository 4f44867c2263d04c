#!/usr/bin/env bash
# The main job on a shipped body (until atlas runs exist): the critical set of the paper's
# type (c) ellipsoid, and the N = -1/7 trajectory of the paper's Fig. xy, with a picture.
# Installs what is missing first (scripts/setup.sh). Output: atlas/out/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bash scripts/setup.sh
echo "quickstart: building rubber-atlas (release)"
cargo build --release --quiet
bin=target/release/rubber-atlas
mkdir -p atlas/out
# The body of the paper's Figs. php, res and xy (atlas/paper-c.body).
. atlas/paper-c.body
echo "quickstart: rubber-atlas diagram --alpha $alpha --beta $beta --nu $nu --eta $eta"
"$bin" diagram --alpha "$alpha" --beta "$beta" --nu "$nu" --eta "$eta" --out atlas/out/paper-c-diagram.h5
echo "quickstart: trajectory of Fig. xy (kappa = 0.8, theta0 = 0.4670288, 7 periods), reduced and full model"
for model in reduced full; do
  "$bin" trajectory --alpha "$alpha" --beta "$beta" --nu "$nu" --eta "$eta" --kappa 0.8 \
    --theta0 0.4670288 --periods 7 --samples 7000 --model "$model" \
    --out "atlas/out/paper-xy-$model.h5"
done
.venv/bin/python scripts/plot_trajectory.py atlas/out/paper-xy-reduced.h5 --out atlas/out/paper-xy.png
echo "quickstart: done; see atlas/out/ (paper-c-diagram.h5, paper-xy-*.h5, paper-xy.png)"
