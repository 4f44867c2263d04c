"""rubber_atlas: the dynamics of a "rubber" ellipsoid of revolution rolling on a plane, from
Python (Kilin & Pivovarova). The numbers come from the same Rust code as the `rubber-atlas`
command, bit for bit; results are xarray objects with the files' names, units and flags.

    import rubber_atlas as ra
    ds = ra.cells(alpha=0.5, beta=3.0, nu=0.5, eta=0.5,
                  kappa=np.linspace(0.1, 2, 200), energy=2.5)   # one solved cell per value
    ds.rotation_number.sel(component=0).plot()
    atlas = ra.open_atlas("atlas/demo.h5")                       # a `rubber-atlas run` file
    atlas.rubber.components(alpha=0.5, beta=3.0, kappa=0.8, energy=2.5)
    atlas.rubber.plot_slice()                                    # a matplotlib Figure
    ra.trajectory(alpha=0.5, beta=3, nu=0.5, eta=0.5, kappa=0.8, energy=2.5, periods=3)
    ra.diagram(alpha=0.5, beta=3), ra.resonance(...), ra.verdict(...), ra.boundaries(...)

Units are the paper's: length b3, mass m, time sqrt(b3/g) (stated in each variable's
`comment`). The extension is built without HDF5: files are read and written by h5py and
h5netcdf, so the only HDF5 library in the process is h5py's.
"""

from __future__ import annotations

from . import _core
from ._api import (
    FIELDS,
    boundaries,
    cells,
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

__version__ = _core.__version__
git_commit = _core.git_commit

__all__ = [
    "FIELDS",
    "RubberAccessor",
    "boundaries",
    "cells",
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
