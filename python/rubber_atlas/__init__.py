"""rubber_atlas: the dynamics of a "rubber" ellipsoid of revolution rolling on a plane, from
Python (Kilin & Pivovarova). The numbers come from the same Rust code as the `rubber-atlas`
command, bit for bit; results are xarray objects with the files' names, units and flags.

Units are the paper's: length b3, mass m, time sqrt(b3/g) (stated in each variable's
`comment`); docs/model.md states the model. The extension is built without HDF5: files are
read and written by h5py and h5netcdf, so the only HDF5 library in the process is h5py's.

- `cells`: solve cells (α, β, ν, η, κ, ε) given as numbers, arrays or DataArrays;
- `open_atlas`: an atlas file of ``rubber-atlas run``, with the ``.rubber`` accessor
  (`RubberAccessor`: ``components``, ``family``, ``plot_slice``);
- `components`, `flag_names`: one cell's components as dicts, the meanings of flags;
- `diagram`, `trajectory`, `resonance`, `read_table`: the critical set, a path, the curves
  N = p/q, and the table files of the command;
- `verdict`, `boundaries`: the paper's boundedness hypothesis, per body and along β.

Examples
--------
The paper's body (α = 0.5, β = 3, ν = η = 0.5) on a small (κ, ε) grid:

>>> import numpy as np
>>> import rubber_atlas as ra
>>> ds = ra.cells(0.5, 3.0, 0.5, 0.5, kappa=np.linspace(0.2, 1.0, 5),
...               energy=np.linspace(1.5, 3.5, 3))
>>> ds.rotation_number.dims
('kappa', 'energy', 'component')
>>> [(c["motion"], round(c["rotation_number"], 4))
...  for c in ds.rubber.components(kappa=0.8, energy=2.5)]
[('libration', -0.8152)]

A path started there, and the critical set of the body:

>>> t = ra.trajectory(0.5, 3.0, 0.5, 0.5, kappa=0.8, energy=2.5, periods=1, samples=50)
>>> t.sizes["t"]
51
>>> import json
>>> json.loads(ra.diagram(0.5, 3.0, samples=100).attrs["critical_set_json"])["diagram_type"]
'c'
"""

from __future__ import annotations

from ._api import (
    FIELDS,
    HAS_CORE,
    boundaries,
    cells,
    census,
    components,
    diagram,
    flag_names,
    open_atlas,
    read_table,
    resonance,
    trajectory,
    verdict,
)
from .accessor import RubberAccessor

from ._api import _core

# Without the compiled core (the source tree on the path) the version is not known.
__version__ = _core.__version__ if HAS_CORE else "unknown (no compiled core)"
git_commit = _core.git_commit if HAS_CORE else "unknown"

__all__ = [
    "FIELDS",
    "HAS_CORE",
    "RubberAccessor",
    "boundaries",
    "cells",
    "census",
    "components",
    "diagram",
    "flag_names",
    "git_commit",
    "open_atlas",
    "read_table",
    "resonance",
    "trajectory",
    "verdict",
]
