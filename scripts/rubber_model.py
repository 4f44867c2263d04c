"""The reduced model of docs/model.md in plain Python, for scripts that check or race rubber-atlas.

Three layers share the formulas of docs/model.md–1.3 (Z, U, B, J, V, ψ̇):
- `HighPrecision`: T and N = −Δψ/2π of the component nearest a given θ, from the mpmath
  reference of `reference.py` at 40 significant digits — an independent reference for the
  hard cells (near a separatrix, a pole or a minimum), where an ODE run is least reliable.
- `midpoint_rotation_numbers`: what a researcher vectorises by hand with NumPy — N alone by
  the periodic midpoint rule after θ = c − (L/2) cos φ.
- `scipy_cell`: what a researcher writes first — turning points by brentq, T and Δψ by
  scipy.integrate.quad.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np

from reference import Cell


class Body:
    """The ellipsoid of docs/model.md: α, β, ν, η."""

    def __init__(self, alpha: float, beta: float, nu: float = 0.5, eta: float = 0.5):
        self.alpha, self.beta, self.nu, self.eta = alpha, beta, nu, eta

    # Formulas generic in the number type (float, numpy array or mpmath mpf), with the
    # trigonometric functions passed in.
    def _z(self, s, c, sqrt):
        return sqrt(self.beta**2 * s * s + c * c)

    def potential(self, theta, kappa, lib=np):
        """V(θ) = κ²/(2 sin²θ) + Z(θ) + α cosθ."""
        s, c = lib.sin(theta), lib.cos(theta)
        return kappa * kappa / (2 * s * s) + self._z(s, c, lib.sqrt) + self.alpha * c

    def slope(self, theta, kappa, lib=np):
        """V′(θ) = −κ² cosθ / sin³θ − α sinθ + (β² − 1) sinθ cosθ / Z."""
        s, c = lib.sin(theta), lib.cos(theta)
        z = self._z(s, c, lib.sqrt)
        return -kappa * kappa * c / s**3 - self.alpha * s + (self.beta**2 - 1) * s * c / z

    def inertia(self, theta, lib=np):
        """B(θ) = 1/η + (β⁴ sin²θ + (cosθ + αZ)²) / Z²."""
        s, c = lib.sin(theta), lib.cos(theta)
        z = self._z(s, c, lib.sqrt)
        return 1 / self.eta + (self.beta**4 * s * s + (c + self.alpha * z) ** 2) / (z * z)

    def integral_factor(self, theta, lib=np):
        """J(θ) = √((cos²θ + ν sin²θ)/η + (Z + α cosθ)²)."""
        s, c = lib.sin(theta), lib.cos(theta)
        z = self._z(s, c, lib.sqrt)
        return lib.sqrt((c * c + self.nu * s * s) / self.eta + (z + self.alpha * c) ** 2)

    def psi_rate(self, theta, kappa, lib=np):
        """ψ̇ = −κ cosθ / (J sin²θ)."""
        s, c = lib.sin(theta), lib.cos(theta)
        return -kappa * c / (self.integral_factor(theta, lib) * s * s)


class _Mp:
    """mpmath under the names the formulas use."""

    sin, cos, sqrt = staticmethod(mpmath.sin), staticmethod(mpmath.cos), staticmethod(mpmath.sqrt)


class HighPrecision:
    """T and N of the component of {V ≤ ε} around a given θ, at `digits` significant digits:
    the component nearest θ among those `reference.Cell` finds."""

    def __init__(self, body: Body, kappa: float, digits: int = 40):
        self.body, self.kappa, self.digits = body, mpmath.mpf(kappa), digits
        self.cell = Cell(body.alpha, body.beta, body.nu, body.eta, kappa, digits)

    def _v(self, theta):
        return self.body.potential(theta, self.kappa, _Mp)

    def _dv(self, theta):
        return self.body.slope(theta, self.kappa, _Mp)

    def critical_points(self):
        """θ of every critical point of V in (0, π) (κ ≠ 0), increasing."""
        with mpmath.workdps(self.digits):
            return [p.theta for p in self.cell.critical_points()]

    def integrals(self, energy: float, near: float):
        """(θ_min, θ_max, T, N) of the component nearest `near`, as floats."""
        comps = self.cell.components(energy)
        best = min(comps, key=lambda c: max(c.theta_min - near, near - c.theta_max, 0.0))
        return best.theta_min, best.theta_max, best.period, best.rotation_number


def midpoint_rotation_numbers(body: Body, kappas, energies, nodes: int = 64, grid: int = 128):
    """N for every (κ, ε) of a grid, for the libration around the lowest minimum of V,
    vectorised over the cells: V on a θ-grid of `grid` points locates the minimum and the first
    grid points above ε on either side, 50 bisections refine the turning points, and the
    periodic midpoint rule in φ after θ = c − (L/2) cos φ with `nodes` nodes on [0, π] gives
    Δψ. The way a researcher computes N alone with NumPy: no error control, NaN where ε is
    below the minimum."""
    kappa, energy = np.meshgrid(np.asarray(kappas, float), np.asarray(energies, float), indexing="ij")
    kappa, energy = kappa.ravel()[:, None], energy.ravel()[:, None]
    theta = np.linspace(1e-9, math.pi - 1e-9, grid)[None, :]
    v = body.potential(theta, kappa)
    index = np.arange(grid)[None, :]
    lowest = np.argmin(v, axis=1)[:, None]
    above = v > energy
    # First grid point above ε right of the minimum, last one left of it (else the poles).
    right = np.where(above & (index > lowest), index, grid - 1).min(axis=1)
    left = np.where(above & (index < lowest), index, 0).max(axis=1)
    step = theta[0, 1] - theta[0, 0]
    kappa, energy = kappa[:, 0], energy[:, 0]

    def root(inside, outside):
        # V(inside) ≤ ε < V(outside): halve the bracket 50 times.
        for _ in range(50):
            mid = 0.5 * (inside + outside)
            out = body.potential(mid, kappa) > energy
            outside, inside = np.where(out, mid, outside), np.where(out, inside, mid)
        return 0.5 * (inside + outside)

    theta_min = root(theta[0, left] + step, theta[0, left])
    theta_max = root(theta[0, right] - step, theta[0, right])
    phi = (np.arange(nodes) + 0.5) * math.pi / nodes
    c, half = 0.5 * (theta_min + theta_max), 0.5 * (theta_max - theta_min)
    t = c[:, None] - half[:, None] * np.cos(phi)[None, :]
    gap = energy[:, None] - body.potential(t, kappa[:, None])
    with np.errstate(invalid="ignore"):  # cells without motion: NaN, masked below
        dt = np.sqrt(body.inertia(t) / (2 * gap)) * half[:, None] * np.sin(phi)[None, :]
    advance = 2 * math.pi / nodes * np.sum(body.psi_rate(t, kappa[:, None]) * dt, axis=1)
    n = -advance / (2 * math.pi)
    n[energy <= v.min(axis=1)] = np.nan
    return n.reshape(len(kappas), len(energies))


def scipy_cell(body: Body, kappa: float, energy: float, tol: float = 1e-10):
    """(T, N) of the libration around the lowest minimum of V with SciPy: the minimum by
    minimize_scalar, the turning points by brentq, T and Δψ by quad (which copes with the
    1/√ ends by its own extrapolation)."""
    from scipy import integrate, optimize

    v = lambda t: body.potential(t, kappa, math_lib)  # noqa: E731
    centre = optimize.minimize_scalar(v, bounds=(1e-6, math.pi - 1e-6), method="bounded").x
    theta_min = optimize.brentq(lambda t: v(t) - energy, 1e-12, centre, xtol=1e-15)
    theta_max = optimize.brentq(lambda t: v(t) - energy, centre, math.pi - 1e-12, xtol=1e-15)

    def dt(t):
        return math.sqrt(body.inertia(t, math_lib) / (2 * max(energy - v(t), 1e-300)))

    period = 2 * integrate.quad(dt, theta_min, theta_max, epsabs=0, epsrel=tol, limit=200)[0]
    advance = 2 * integrate.quad(
        lambda t: body.psi_rate(t, kappa, math_lib) * dt(t), theta_min, theta_max, epsabs=tol, epsrel=tol, limit=200
    )[0]
    return period, -advance / (2 * math.pi)


class _Math:
    sin, cos, sqrt = staticmethod(math.sin), staticmethod(math.cos), staticmethod(math.sqrt)


math_lib = _Math
