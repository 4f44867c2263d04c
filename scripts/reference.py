"""An independent high-precision reference for one cell of rubber-atlas: every component of
{V ≤ ε}, its turning points, T and N = −Δψ/2π, by mpmath at 50 significant digits.

It shares no code with the Rust solver, only the formulas of docs/model.md–1.3. Points near a pole
are held in the pole's chart (θ or π − θ), so that turning points at 1e-100 from a pole keep
their digits; the critical points of V are the roots of g = sin³θ V′, found by a scan that is
uniform in the middle and logarithmic towards both poles, where g′ and g are both scanned so
that a pair of close roots between two scan points is not missed; T and Δψ are tanh-sinh
quadratures (mpmath.quad) split at every critical point and at π/2, each with its own error
estimate, which must be far below the solver's.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import mpmath

DIGITS = 50
# Digits the quadrature rule is run to (its integrand is evaluated at DIGITS).
QUAD_DIGITS = 24


@dataclass(frozen=True)
class Point:
    """θ held in the chart of its nearer pole: θ = x (side 0) or θ = π − x (side 1)."""

    x: mpmath.mpf
    side: int

    @property
    def theta(self):
        return self.x if self.side == 0 else mpmath.pi - self.x

    def sin_cos(self):
        s, c = mpmath.sin(self.x), mpmath.cos(self.x)
        return (s, c) if self.side == 0 else (s, -c)


def at(theta) -> Point:
    theta = mpmath.mpf(theta)
    return Point(theta, 0) if theta <= mpmath.pi / 2 else Point(mpmath.pi - theta, 1)


@dataclass
class Component:
    """[θ_min, θ_max] (on the κ = 0 circle θ_min may be negative), its kind, and T, N with the
    quadrature's own error estimates."""

    theta_min: float
    theta_max: float
    kind: str
    period: float
    rotation_number: float
    period_error: float
    rotation_error: float


class Cell:
    """V(θ) = κ²/(2 sin²θ) + Z(θ) + α cosθ of one (body, κ), at `digits` digits."""

    def __init__(self, alpha, beta, nu, eta, kappa, digits: int = DIGITS):
        self.digits = digits
        with mpmath.workdps(digits):
            self.alpha, self.beta, self.nu, self.eta, self.kappa = map(mpmath.mpf, (alpha, beta, nu, eta, kappa))

    # Shape functions of docs/model.md at (sin θ, cos θ).
    def _z(self, s, c):
        return mpmath.sqrt(self.beta**2 * s * s + c * c)

    def potential(self, p: Point):
        s, c = p.sin_cos()
        u = self._z(s, c) + self.alpha * c
        return u if self.kappa == 0 else self.kappa**2 / (2 * s * s) + u

    def g(self, p: Point):
        """sin³θ V′(θ) = −κ² cosθ + sin³θ U′(θ): no pole."""
        s, c = p.sin_cos()
        u_prime = -self.alpha * s + (self.beta**2 - 1) * s * c / self._z(s, c)
        return -self.kappa**2 * c + s**3 * u_prime

    def inertia(self, s, c):
        z = self._z(s, c)
        return 1 / self.eta + (self.beta**4 * s * s + (c + self.alpha * z) ** 2) / (z * z)

    def integral_factor(self, s, c):
        z = self._z(s, c)
        return mpmath.sqrt((c * c + self.nu * s * s) / self.eta + (z + self.alpha * c) ** 2)

    def kinks(self) -> list[Point]:
        """Where U″ jumps (none on the ellipsoid): the integrals are cut there."""
        return []

    def splits(self) -> list[Point]:
        """Where the integrals are cut besides the critical points: the kinks, and about each
        zero of U (where 1/J peaks, as narrowly as √((cos²θ + ν sin²θ)/η)/|U′|: a disk with
        α = 68, η = 3805 had its N 1e-9 off from a quadrature that stepped over the peak)."""
        with mpmath.workdps(self.digits):
            points = list(self.kinks()) + self.turns()
            for zero in self.potential_zeros():
                for offset in _PEAK_OFFSETS:
                    if 0 < zero + offset < mpmath.pi:
                        points.append(at(zero + offset))
            return sorted(points, key=lambda p: p.theta)

    def potential_zeros(self) -> list:
        """θ in (0, π) where U = 0 (none on the ellipsoid, whose U is positive)."""
        return []

    def turns(self) -> list[Point]:
        """Cuts about where Z = √(β² sin²θ + cos²θ) turns: within β of π/2 on a needle
        (β < 1e-2), within 1/β of the poles on a flat body (β > 1e2), geometrically spaced down
        to a hundredth of that width (a needle at β = 1.3e-8 had T 1.4e-12 off, relative, from a
        quadrature that stepped over the turn at π/2)."""
        if self.beta < mpmath.mpf("1e-2"):
            width = self.beta
            return [at(mpmath.pi / 2 + sign * width * mpmath.mpf(10) ** (k / mpmath.mpf(2)))
                    for k in range(-4, 7) for sign in (-1, 1)]
        if self.beta > mpmath.mpf("1e2"):
            width = 1 / self.beta
            return [Point(width * mpmath.mpf(10) ** (k / mpmath.mpf(2)), side)
                    for k in range(-4, 7) for side in (0, 1)]
        return []

    # Critical points.
    def _scan(self):
        """Scan points in (0, π) as chart points: log-spaced towards both poles, uniform between."""
        tiny = mpmath.mpf(10) ** (-min(self.digits * 2, 300))
        if self.kappa != 0:
            # The critical point nearest a pole sits at θ³ ≈ κ²/|U″|: reach far below it.
            tiny = min(tiny, abs(self.kappa) ** mpmath.mpf(2) / 10**6)
        logs = [tiny * (mpmath.mpf(0.1) / tiny) ** (mpmath.mpf(i) / 400) for i in range(400)]
        middle = [mpmath.mpf(0.1) + (mpmath.pi / 2 - mpmath.mpf(0.1)) * i / 1500 for i in range(1501)]
        left = [Point(x, 0) for x in logs + middle]
        right = [Point(x, 1) for x in reversed(logs + middle[:-1])]
        return left + right

    def critical_points(self) -> list[Point]:
        """Roots of g in (0, π), sorted by θ (κ ≠ 0), or of U′ on (0, π) plus 0 and π (κ = 0)."""
        with mpmath.workdps(self.digits):
            # The kinks too: a maximum and a minimum of V may sit on either side of one, closer
            # than the scan's step, where g dips below zero at the kink alone.
            grid = sorted(self._scan() + self.kinks(), key=lambda p: p.theta)
            values = [self.g(p) for p in grid]
            roots = []
            if all(v == 0 for v in values):
                # A flat U at κ = 0 (the homogeneous sphere): no isolated critical points.
                grid, values = [], []
            for i in range(len(grid) - 1):
                a, b, fa, fb = grid[i], grid[i + 1], values[i], values[i + 1]
                if fa == 0:
                    roots.append(a)
                elif fa * fb < 0:
                    roots.append(self._bisect_points(self.g, a, b))
                elif 0 < i and fa * values[i - 1] > 0 and abs(fa) < abs(values[i - 1]) and abs(fa) <= abs(fb):
                    # |g| has a local minimum near a: a pair of roots may hide there.
                    roots.extend(self._hidden_pair(grid[i - 1], b))
            roots = sorted(set(roots), key=lambda p: p.theta)
            if self.kappa == 0:
                eps = mpmath.mpf(10) ** (-self.digits // 2)
                roots = [Point(mpmath.mpf(0), 0)] + [r for r in roots if r.x > eps] + [Point(mpmath.mpf(0), 1)]
            return roots

    def _hidden_pair(self, a: Point, b: Point):
        """Roots of g between a and b when g keeps its sign at both: minimise |g| by golden
        section; if g changes sign at the minimiser, bisect both sides."""
        if a.side != b.side:
            return []
        f = lambda x: abs(self.g(Point(x, a.side)))  # noqa: E731
        lo, hi = min(a.x, b.x), max(a.x, b.x)
        ratio = (mpmath.sqrt(5) - 1) / 2
        for _ in range(200):
            m1, m2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
            if f(m1) < f(m2):
                hi = m2
            else:
                lo = m1
        m = Point((lo + hi) / 2, a.side)
        gm, ga = self.g(m), self.g(a)
        if gm == 0 or gm * ga > 0:
            return [m] if gm == 0 else []
        return [self._bisect_points(self.g, a, m), self._bisect_points(self.g, m, b)]

    def _bisect_points(self, f, a: Point, b: Point) -> Point:
        """A sign change of f between chart points a and b (same side or across π/2)."""
        if a.side != b.side:
            mid = Point(mpmath.pi / 2, 0)
            fm = f(mid)
            if fm == 0:
                return mid
            return self._bisect_points(f, a, mid) if f(a) * fm < 0 else self._bisect_points(f, Point(mpmath.pi / 2, 1), b)
        side = a.side
        lo, hi = a.x, b.x
        flo, fhi = f(a), f(b)
        if (flo > 0) == (fhi > 0):
            # No sign change left (the root sits at an end to the working precision, as at
            # θ = π/2 seen from both charts).
            return a if abs(flo) <= abs(fhi) else b
        eps = mpmath.mpf(2) ** (-mpmath.mp.prec + 2)
        while abs(hi - lo) > eps * max(abs(lo), abs(hi)):
            mid = (lo + hi) / 2
            fm = f(Point(mid, side))
            if fm == 0:
                return Point(mid, side)
            if (fm > 0) == (flo > 0):
                lo, flo = mid, fm
            else:
                hi = mid
        return Point((lo + hi) / 2, side)

    # Components and integrals.
    def components(self, energy, quad_digits: int | None = None) -> list[Component]:
        """Every component of {V ≤ ε} with T and N (an empty list: no motion)."""
        with mpmath.workdps(self.digits):
            e = mpmath.mpf(energy)
            crit = self.critical_points()
            if self.kappa == 0:
                return self._circle(e, crit)
            nodes = [None] + crit + [None]
            level = lambda p: self.potential(p) - e  # noqa: E731
            inside = [n is not None and level(n) <= 0 for n in nodes]
            ends: list[Point] = []
            for i in range(len(nodes) - 1):
                if inside[i] == inside[i + 1]:
                    continue
                a = nodes[i] if nodes[i] is not None else Point(mpmath.mpf(0), 0)
                b = nodes[i + 1] if nodes[i + 1] is not None else Point(mpmath.mpf(0), 1)
                # A pole is +∞: start the bisection just inside it, where V > ε surely.
                if nodes[i] is None:
                    a = self._inside_pole(0, e, crit[0].x if crit and crit[0].side == 0 else None)
                if nodes[i + 1] is None:
                    b = self._inside_pole(1, e, crit[-1].x if crit and crit[-1].side == 1 else None)
                ends.append(self._bisect_points(level, a, b))
            result = []
            for lo, hi in zip(ends[0::2], ends[1::2]):
                interior = [c for c in crit if lo.theta < c.theta < hi.theta]
                period, advance, et, ea = self._integrate(e, lo, hi, interior)
                result.append(
                    Component(float(lo.theta), float(hi.theta), "libration", float(period),
                              float(-advance / (2 * mpmath.pi)), float(et), float(ea / (2 * mpmath.pi)))
                )
            return result

    def _inside_pole(self, side: int, e, nearest=None) -> Point:
        """A point between the pole and its nearest critical point where V > ε (κ ≠ 0)."""
        x = mpmath.mpf("1e-3") if nearest is None else min(mpmath.mpf("1e-3"), nearest / 2)
        while self.potential(Point(x, side)) <= e:
            x /= 10
        return Point(x, side)

    def _circle(self, e, crit) -> list[Component]:
        """κ = 0: U on the circle, symmetric in θ → −θ; critical points 0, roots, π."""
        values = [self.potential(c) for c in crit]
        top = max(values)
        if e > top:
            # Rolling over the top: T = 2 ∫₀^π (both halves of the circle).
            period, _, et, _ = self._integrate(e, Point(mpmath.mpf(0), 0), Point(mpmath.mpf(0), 1), crit[1:-1], ends=False)
            peak = crit[values.index(top)].theta
            return [Component(float(peak), float(peak + 2 * mpmath.pi), "rotation", float(period / 2 * 2), 0.0, float(et), 0.0)]
        if e < min(values):
            return []
        level = lambda p: self.potential(p) - e  # noqa: E731
        # Turning points on [0, π] (θ ≥ 0); the components around 0 and π are mirrored.
        ends = []
        for a, b, va, vb in zip(crit, crit[1:], values, values[1:]):
            if (va <= e) != (vb <= e):
                ends.append(self._bisect_points(level, a, b))
        result = []
        marks = ([crit[0]] if values[0] <= e else []) + ends + ([crit[-1]] if values[-1] <= e else [])
        for lo, hi in zip(marks[0::2], marks[1::2]):
            interior = [c for c in crit if lo.theta < c.theta < hi.theta]
            at_zero, at_pi = lo.theta == 0, hi.theta == mpmath.pi
            period, _, et, _ = self._integrate(e, lo, hi, interior, ends=False)
            # Half of a libration: ×2 (integral out and back); around a pole ×2 again.
            factor = 2 * (2 if at_zero or at_pi else 1)
            t_min = -hi.theta if at_zero else lo.theta
            t_max = 2 * mpmath.pi - lo.theta if at_pi else hi.theta
            comp = Component(float(t_min), float(t_max), "libration", float(period / 2 * factor), 0.0,
                             float(et / 2 * factor), 0.0)
            result.append(comp)
            if not (at_zero or at_pi):
                # The mirror image θ → 2π − θ is a component of its own on the circle.
                result.append(Component(float(2 * mpmath.pi - hi.theta), float(2 * mpmath.pi - lo.theta), "libration",
                                        comp.period, 0.0, comp.period_error, 0.0))
        return result

    def _integrate(self, e, lo: Point, hi: Point, interior, ends: bool = True):
        """(T, Δψ, error T, error Δψ) of a libration between turning points lo < hi: twice the
        integrals over [θ_min, θ_max], split at interior critical points and π/2."""
        kinks = [k for k in self.splits() if lo.theta < k.theta < hi.theta]
        cuts = sorted([lo] + list(interior) + kinks + [hi], key=lambda p: p.theta)
        half = Point(mpmath.pi / 2, 0)
        if lo.theta < mpmath.pi / 2 < hi.theta and all(abs(c.theta - mpmath.pi / 2) > 1e-20 for c in cuts):
            cuts = sorted(cuts + [half], key=lambda p: p.theta)
        period, advance, et, ea = mpmath.mpf(0), mpmath.mpf(0), mpmath.mpf(0), mpmath.mpf(0)
        for a, b in zip(cuts, cuts[1:]):
            if a.theta == b.theta:
                continue
            side = 0 if b.theta <= mpmath.pi / 2 else 1
            xa = a.x if a.side == side else mpmath.pi - a.x
            xb = b.x if b.side == side else mpmath.pi - b.x

            lo_x, hi_x = min(xa, xb), max(xa, xb)
            width = hi_x - lo_x

            def rates(u, side=side, start=lo_x, step=width):
                # dt/dθ + i ψ̇ dt/dθ at θ = start + step·u, evaluated at the full precision (the
                # nodes u near 0 keep their distance to the turning point exactly).
                with mpmath.workdps(self.digits):
                    p = Point(start + step * u, side)
                    gap = e - self.potential(p)
                    if gap <= 0:
                        return mpmath.mpc(0)
                    s, c = p.sin_cos()
                    dt = mpmath.sqrt(self.inertia(s, c) / (2 * gap))
                    psi = -self.kappa * c / (self.integral_factor(s, c) * s * s) if self.kappa != 0 else 0
                    return mpmath.mpc(dt, psi * dt) * abs(step)

            # Each half measured from its own end, where the singularity sits; the rule itself
            # runs at QUAD_DIGITS (its error estimate must reach 1e-30, not 1e-50).
            value, err = mpmath.mpc(0), mpmath.mpf(0)
            for start, step in ((lo_x, width), (hi_x, -width)):
                with mpmath.workdps(QUAD_DIGITS):
                    # u = w² removes the 1/√u of a turning point (mpmath's nodes near an end lose
                    # digits to 1 + x, so the singularity must not sit there).
                    v, er = mpmath.quad(lambda w: 2 * w * rates(w * w, start=start, step=step),
                                        _splits(start / width if self.kappa != 0 else 1), error=True, maxdegree=10)
                value += v
                err += er
            t, a_, t_err, a_err = value.real, value.imag, err, err
            period += t
            advance += a_
            et += t_err
            ea += a_err
        return 2 * period, 2 * advance, 2 * et, 2 * ea


class EdgedCell(Cell):
    """V of one (body, κ) of the disk, the truncated ball or the wheel (docs/bodies.md): on each
    part of the surface U = p|sinθ| + q cosθ + r (an edge: r = 0; the sphere: p = 0, r = 1),
    |r|² = U² + U′², J = √((cos²θ + ν sin²θ)/η + U²). At κ = 0 a component that reaches a
    flat face (θ = 0 of the cut balls, θ = π of the wheel, both poles of the disk) is of kind
    "reaches_face": the motion ends there (docs/bodies.md), with no T."""

    def turns(self) -> list[Point]:
        """None: the edged bodies' parts are cut at their kinks."""
        return []

    def __init__(self, kind, alpha, cut, nu, eta, kappa, digits: int = DIGITS):
        super().__init__(alpha, 1, nu, eta, kappa, digits)
        self.kind = kind
        with mpmath.workdps(digits):
            self.cut = mpmath.mpf(0 if kind == "disk" else cut)
            self.rho = mpmath.sqrt(1 - self.cut**2) if kind != "disk" else mpmath.mpf(1)

    def _part(self, c):
        h, rho, a = self.cut, self.rho, self.alpha
        if self.kind == "disk":
            return rho, a, 0
        if c > h:
            return rho, h + a, 0
        if self.kind == "wheel" and c < -h:
            return rho, a - h, 0
        return 0, a, 1

    def _u(self, s, c):
        p, q, r = self._part(c)
        return p * s + q * c + r

    def _u_prime(self, s, c):
        p, q, _ = self._part(c)
        return p * c - q * s

    def potential(self, p: Point):
        s, c = p.sin_cos()
        return self._u(s, c) if self.kappa == 0 else self.kappa**2 / (2 * s * s) + self._u(s, c)

    def g(self, p: Point):
        s, c = p.sin_cos()
        return -self.kappa**2 * c + s**3 * self._u_prime(s, c)

    def inertia(self, s, c):
        return 1 / self.eta + self._u(s, c) ** 2 + self._u_prime(s, c) ** 2

    def integral_factor(self, s, c):
        return mpmath.sqrt((c * c + self.nu * s * s) / self.eta + self._u(s, c) ** 2)

    def faces(self) -> tuple[bool, bool]:
        """Whether the body has a flat face at θ = 0 and at θ = π."""
        return {"disk": (True, True), "truncated_ball": (True, False), "wheel": (True, True)}[self.kind]

    def _circle(self, e, crit) -> list[Component]:
        faces = self.faces()
        result = []
        for comp in super()._circle(e, crit):
            # On the lifted circle the poles are the multiples of π: 2πm (face 0), π + 2πm.
            first = math.ceil(comp.theta_min / math.pi - 1e-15)
            last = math.floor(comp.theta_max / math.pi + 1e-15)
            if any(faces[k % 2] for k in range(first, last + 1)):
                comp = Component(comp.theta_min, comp.theta_max, "reaches_face", math.nan, 0.0, math.nan, 0.0)
            result.append(comp)
        return result

    def kinks(self) -> list[Point]:
        if self.kind == "disk":
            return []
        with mpmath.workdps(self.digits):
            theta_c = mpmath.acos(self.cut)
            # θ_c from its own pole's chart, π − θ_c from the other.
            kinks = [at(theta_c)]
            if self.kind == "wheel":
                kinks.append(at(mpmath.pi - theta_c))
            return kinks

    def potential_zeros(self) -> list:
        with mpmath.workdps(self.digits):
            h, rho, a = self.cut, self.rho, self.alpha
            if self.kind == "disk":
                parts = [(rho, a, 0, 0, mpmath.pi)]
            else:
                theta_c = mpmath.acos(h)
                parts = [(rho, h + a, 0, 0, theta_c), (0, a, 1, theta_c, mpmath.pi)]
                if self.kind == "wheel":
                    parts[1] = (0, a, 1, theta_c, mpmath.pi - theta_c)
                    parts.append((rho, a - h, 0, mpmath.pi - theta_c, mpmath.pi))
            return [z for p, q, r, lo, hi in parts for z in _trig_zeros(p, q, r, lo, hi)]


class ProfileCell(EdgedCell):
    """V of one (body, κ) of a profile (docs/bodies.md, "Your own body"): the arc spline through
    a table of meridian points, fitted here anew at `digits` digits by the rules that page
    states (the tangent of the circle through each smooth point and its neighbours, 0 and π at
    smooth poles; two arcs between smooth points with the joint's tangent in the middle of the
    range where both turn one way; one arc beside an edge; the normal turning round an edge;
    a flat end of the table a face). On an arc of centre (ρ_c, z_c) and radius r,
    U = ρ_c sinθ − (z_c − α) cosθ + r. κ ≠ 0 only."""

    def __init__(self, rows, alpha, nu, eta, kappa, digits: int = DIGITS):
        if kappa == 0:
            raise ValueError("ProfileCell: kappa = 0 (its faces depend on the table) is not covered")
        EdgedCell.__init__(self, "disk", alpha, None, nu, eta, kappa, digits)
        self.kind = "profile"
        with mpmath.workdps(digits):
            self.arcs = _profile_arcs([[mpmath.mpf(x) for x in r] for r in rows])

    def _arc(self, s, c):
        theta = mpmath.atan2(s, c)
        for arc in self.arcs:
            if theta <= arc[1]:
                return arc
        return self.arcs[-1]

    def _u(self, s, c):
        _, _, r, rho_c, z_c = self._arc(s, c)
        return rho_c * s - (z_c - self.alpha) * c + r

    def _u_prime(self, s, c):
        _, _, _, rho_c, z_c = self._arc(s, c)
        return rho_c * c + (z_c - self.alpha) * s

    def kinks(self) -> list[Point]:
        with mpmath.workdps(self.digits):
            return [at(arc[1]) for arc in self.arcs[:-1]]

    def potential_zeros(self) -> list:
        with mpmath.workdps(self.digits):
            return [
                z
                for lo, hi, r, rho_c, z_c in self.arcs
                for z in _trig_zeros(rho_c, -(z_c - self.alpha), r, lo, hi)
            ]


# Cuts about a zero of U (`Cell.splits`): at it and on a geometric ladder either side, so that
# the peak of 1/J there, however narrow, lies at the ends of pieces, where the nodes crowd.
_PEAK_OFFSETS = [0] + [sign * mpmath.mpf(10) ** (-k / 2) for k in range(3, 13) for sign in (-1, 1)]


def _trig_zeros(a, b, r, lo, hi) -> list:
    """The θ in (lo, hi) where a sinθ + b cosθ + r = 0."""
    size = mpmath.sqrt(a * a + b * b)
    if size == 0 or abs(r) > size:
        return []
    phase = mpmath.atan2(b, a)
    base = mpmath.asin(-r / size)
    found = []
    for theta in (base - phase, mpmath.pi - base - phase):
        for turns in (-1, 0, 1):
            x = theta + 2 * mpmath.pi * turns
            if lo < x < hi:
                found.append(x)
    return found


def _same(x, y) -> bool:
    """Equal to within the working precision (a tangent taken from this chord)."""
    return abs(x - y) <= mpmath.mpf(10) ** (-mpmath.mp.dps + 8)


def _profile_arcs(rows):
    """The arcs (θ_start, θ_end, r, ρ_c, z_c) of the arc spline through `rows` (ρ, z[, edge]),
    in order of the normal angle θ from 0 to π (r = 0 round an edge)."""
    if rows[0][1] > rows[-1][1]:
        rows = rows[::-1]
    n = len(rows)
    pi = mpmath.pi
    faces = (rows[1][1] == rows[0][1], rows[n - 2][1] == rows[n - 1][1])
    first, last = (1 if faces[0] else 0), (n - 2 if faces[1] else n - 1)

    def edge(i):
        return (len(rows[i]) > 2 and rows[i][2] == 1) or (i == first and faces[0]) or (i == last and faces[1])

    def chord(a, b):
        return mpmath.atan2(b[1] - a[1], b[0] - a[0]), mpmath.hypot(b[0] - a[0], b[1] - a[1])

    tangent = {}
    for i in range(first, last + 1):
        if edge(i):
            continue
        if i == 0:
            tangent[i] = mpmath.mpf(0)
        elif i == n - 1:
            tangent[i] = pi
        else:
            (psi1, l1), (psi2, l2) = chord(rows[i - 1], rows[i]), chord(rows[i], rows[i + 1])
            turn = psi2 - psi1
            assert 0 < turn < pi, f"not convex at point {i}"
            tangent[i] = psi1 + mpmath.atan2(l1 * mpmath.sin(turn), l2 + l1 * mpmath.cos(turn))

    def arc(t0, t1, r, anchor_theta, anchor):
        # The centre: the anchor less r times the outward normal (sin θ_a, −cos θ_a).
        return (t0, t1, r, anchor[0] - r * mpmath.sin(anchor_theta), anchor[1] + r * mpmath.cos(anchor_theta))

    # The tangents where the meridian arrives at and leaves each edge; one between the chords
    # where the one-arc tangents would overshoot.
    arrive, leave = {}, {}
    for i in range(first, last + 1):
        if not edge(i):
            continue
        bottom = i == 0 or (i == first and faces[0])
        top = i == n - 1 or (i == last and faces[1])
        arrive[i] = mpmath.mpf(0) if bottom else 2 * chord(rows[i - 1], rows[i])[0] - tangent[i - 1]
        leave[i] = pi if top else 2 * chord(rows[i], rows[i + 1])[0] - tangent[i + 1]
        if arrive[i] > leave[i]:
            if bottom:
                common = arrive[i]
            elif top:
                common = leave[i]
            else:
                before, after = chord(rows[i - 1], rows[i])[0], chord(rows[i], rows[i + 1])[0]
                margin = (after - before) / 4
                common = min(max((arrive[i] + leave[i]) / 2, before + margin), after - margin)
            arrive[i] = leave[i] = common

    arcs = []
    for i in range(first, last):
        a, b = rows[i], rows[i + 1]
        psi, length = chord(a, b)
        if edge(i):
            arcs.append(arc(arrive[i], leave[i], 0, arrive[i], a))
        t0 = leave[i] if edge(i) else tangent[i]
        t1 = arrive[i + 1] if edge(i + 1) else tangent[i + 1]
        assert t0 < psi < t1, f"not convex between points {i} and {i + 1}"
        # One arc beside an edge whose tangent was taken from this chord, else a biarc.
        one_arc = _same(t1, 2 * psi - t0) or _same(t0, 2 * psi - t1)
        if one_arc:
            r = length / (2 * mpmath.sin((t1 - t0) / 2))
            arcs.append(arc(t0, t1, r, *((t0, a) if edge(i + 1) else (t1, b))))
            continue
        lo, hi = max(t0, 2 * psi - t1), min(t1, 2 * psi - t0)
        tj = (lo + hi) / 2
        m1, m2 = (t0 + tj) / 2, (tj + t1) / 2
        det = mpmath.sin(m2 - m1)
        c1, c2 = length * mpmath.sin(m2 - psi) / det, length * mpmath.sin(psi - m1) / det
        arcs.append(arc(t0, tj, c1 / (2 * mpmath.sin((tj - t0) / 2)), t0, a))
        arcs.append(arc(tj, t1, c2 / (2 * mpmath.sin((t1 - tj) / 2)), t1, b))
    if edge(last):
        arcs.append(arc(arrive[last], leave[last], 0, arrive[last], rows[last]))
    arcs = [a for a in arcs if a[1] > a[0]]
    assert arcs[0][0] == 0 and abs(arcs[-1][1] - pi) < mpmath.mpf(10) ** (-mpmath.mp.dps + 5)
    return arcs


def edged_reference(kind, alpha, cut, nu, eta, kappa, energy, digits: int = DIGITS) -> list[Component]:
    """The components of a cell of an edged body with T and N at `digits` digits."""
    return EdgedCell(kind, alpha, cut, nu, eta, kappa, digits).components(energy)


def _splits(distance):
    """Points in w = √u for one half-piece whose end lies `distance` (in units of the piece's
    width) from the pole: ψ̇ ~ κ/θ² and the turning point's curvature vary on that scale, which
    mpmath's nodes cannot resolve near an end, so the half is cut geometrically down to it."""
    top = mpmath.sqrt(mpmath.mpf(0.5))
    if distance >= mpmath.mpf("1e-3") or distance <= 0:
        return [0, top]
    points = [top]
    while points[-1] ** 2 > distance / 10:
        points.append(points[-1] / 4)
    return [0] + points[::-1]


def reference(alpha, beta, nu, eta, kappa, energy, digits: int = DIGITS) -> list[Component]:
    """The components of the cell (α, β, ν, η, κ, ε) with T and N at `digits` digits."""
    return Cell(alpha, beta, nu, eta, kappa, digits).components(energy)


def _libration_rates(alpha, beta, nu, eta, kappa, energy, theta_min, theta_max, degree, digits):
    """For `libration_drift`s (inside mpmath.workdps(digits)): the function φ ↦ (dt/dφ, ψ̇ dt/dφ,
    dθ/dφ, U, κ/(J sinθ)) at θ = θ_min + L (1 − cos φ)/2, the turning points refined to `digits`,
    and the Gauss–Legendre rule of `degree` on [−1, 1]."""
    cell = Cell(alpha, beta, nu, eta, kappa, digits)
    e = mpmath.mpf(energy)

    def end(theta):
        return mpmath.findroot(lambda x: cell.potential(at(x)) - e, mpmath.mpf(theta), tol=mpmath.mpf(10) ** (-digits + 5))

    lo, hi = end(theta_min), end(theta_max)
    length = hi - lo

    def rates(phi):
        theta = lo + length * (1 - mpmath.cos(phi)) / 2
        s, c = mpmath.sin(theta), mpmath.cos(theta)
        slope = length * mpmath.sin(phi) / 2
        gap = e - cell.potential(at(theta))
        dt = mpmath.sqrt(cell.inertia(s, c) / (2 * gap)) * abs(slope) if gap > 0 else mpmath.mpf(0)
        j = cell.integral_factor(s, c)
        u = cell._z(s, c) + cell.alpha * c
        return dt, -cell.kappa * c / (j * s * s) * dt, slope, u, cell.kappa / (j * s)

    rule = mpmath.calculus.quadrature.GaussLegendre(mpmath.mp)
    return rates, rule.calc_nodes(degree, mpmath.mp.prec)


def libration_drift(alpha, beta, nu, eta, kappa, energy, theta_min, theta_max, degree: int = 6,
                    digits: int = DIGITS):
    """(|Δζ|, Δψ) of the libration of the ellipsoid cell (α, β, ν, η, κ ≠ 0, ε) between the
    turning points near `theta_min` and `theta_max` (refined here to `digits`), for a libration
    with no critical point of V inside.

    Δζ = ∫ ζ̇ dt over one θ-period from θ_min, with ζ̇ = −U e^{iψ} (κ/(J sinθ) + i θ̇) (docs/model.md),
    in the variable φ ∈ [0, 2π] of θ = θ_min + L (1 − cos φ)/2 (the way out, then back):
    dt/dφ = √(B/(2(ε − V))) L |sin φ|/2 and θ̇ dt/dφ = L sin φ/2, both analytic and periodic in φ.
    Gauss–Legendre on [0, 2π] with 3·2^(degree−1) nodes, and ψ(φ) at each node by a rule of its
    own over [0, φ]: no symmetry of the orbit and nothing of the solver's (a trapezoid rule and a
    spectral antiderivative over the way out alone). Compare two degrees for its error."""
    with mpmath.workdps(digits):
        rates, unit = _libration_rates(alpha, beta, nu, eta, kappa, energy, theta_min, theta_max, degree, digits)

        def integral(f, a, b):
            half = (b - a) / 2
            return half * mpmath.fsum(w * f(a + half * (x + 1)) for x, w in unit)

        def psi_at(phi):
            return integral(lambda t: rates(t)[1], mpmath.mpf(0), phi)

        def velocity(phi):
            dt, _, slope, u, along = rates(phi)
            return -u * mpmath.expj(psi_at(phi)) * mpmath.mpc(along * dt, slope)

        drift = integral(velocity, mpmath.mpf(0), 2 * mpmath.pi)
        return abs(drift), psi_at(2 * mpmath.pi)


def libration_drift_graded(alpha, beta, nu, eta, kappa, energy, theta_min, theta_max, degree: int = 4,
                           grading: int = 30, digits: int = DIGITS):
    """`libration_drift` on panels of φ graded geometrically towards the turning points (φ = 0,
    π and 2π; the smallest panel 2^(−grading) π/2 wide), Gauss–Legendre with 3·2^(degree−1)
    nodes on each, ψ at the nodes integrated from the panel's start by the interpolating
    polynomial of ψ̇ there, and carried from panel to panel: it resolves a sweep by a pole close to a
    turning point and a turning point close to a saddle, where the integrand is analytic but
    nearly singular at the panel's end, which the single rule does not. Compare two degrees
    for its error."""
    with mpmath.workdps(digits):
        rates, unit = _libration_rates(alpha, beta, nu, eta, kappa, energy, theta_min, theta_max, degree, digits)

        # ψ at the nodes of a panel from ψ̇ there: the integrals from the panel's start of the
        # Lagrange polynomials through its nodes (exact for the interpolant of ψ̇).
        xs = [x for x, _ in unit]

        def lagrange(j, t):
            return mpmath.fprod((t - xk) / (xs[j] - xk) for k, xk in enumerate(xs) if k != j)

        antiderivative = [[(x + 1) / 2 * mpmath.fsum(w * lagrange(j, -1 + (x + 1) / 2 * (y + 1)) for y, w in unit)
                           for j in range(len(xs))] for x in xs]
        quarter = mpmath.pi / 2
        near = [quarter * mpmath.mpf(2) ** (-k) for k in range(grading, 0, -1)]
        way = [mpmath.mpf(0)] + near + [quarter] + [mpmath.pi - h for h in reversed(near)] + [mpmath.pi]
        breaks = way + [mpmath.pi + b for b in way[1:]]
        psi, drift = mpmath.mpf(0), mpmath.mpc(0)
        for a, b in zip(breaks, breaks[1:]):
            half = (b - a) / 2
            values = [rates(a + half * (x + 1)) for x in xs]
            for (_, w), row, (dt, _, slope, u, along) in zip(unit, antiderivative, values):
                swept = psi + half * mpmath.fsum(r * v[1] for r, v in zip(row, values))
                drift += half * w * -u * mpmath.expj(swept) * mpmath.mpc(along * dt, slope)
            psi += half * mpmath.fsum(w * v[1] for (_, w), v in zip(unit, values))
        return abs(drift), psi


def critical_levels(alpha, beta, nu, eta, kappa, digits: int = DIGITS) -> list[tuple[float, float]]:
    """(θ, V) of every critical point of V, as floats."""
    cell = Cell(alpha, beta, nu, eta, kappa, digits)
    with mpmath.workdps(digits):
        return [(float(p.theta), float(cell.potential(p))) for p in cell.critical_points()]


def high_energy_rotation_number(cell: Cell, lam, digits: int = DIGITS):
    """N∞(λ), the rotation number at ε → ∞ with λ = κ/√ε fixed (docs/model.md), of the body of
    `cell` (its κ plays no part): (λ/π) ∫ cosθ √B / (J sinθ √(2 sin²θ − λ²)) dθ over
    sinθ ≥ λ/√2, as it stands (no part subtracted; the halves θ ≶ π/2 integrated apart, each
    in its distance d from its turning point, so that sinθ − λ/√2 = 2 cos(θ_min + d/2) sin(d/2)
    keeps its digits), by tanh-sinh split at the kinks and geometrically towards the turning
    points. Returns (value, the quadrature's error estimate)."""
    with mpmath.workdps(digits):
        lam = mpmath.mpf(lam)
        m = lam / mpmath.sqrt(2)
        theta_min = mpmath.asin(m)
        half = mpmath.pi / 2 - theta_min

        def f(d, side):
            a = theta_min + d
            s = mpmath.sin(a)
            c = mpmath.cos(a) * (1 if side == 0 else -1)
            gap = 2 * mpmath.cos(theta_min + d / 2) * mpmath.sin(d / 2)
            b = cell.inertia(s, c)
            j = cell.integral_factor(s, c)
            return c * mpmath.sqrt(b) / (j * s * mpmath.sqrt(2 * gap * (s + m)))

        total, error = mpmath.mpf(0), mpmath.mpf(0)
        for side in (0, 1):
            points = {mpmath.mpf(0), half}
            for k in cell.kinks():
                if k.side == side and theta_min < k.x:
                    points.add(k.x - theta_min)
            step = theta_min
            while step < half / 2:
                points.add(step)
                step *= 2
            points = sorted(points)
            with mpmath.workdps(QUAD_DIGITS + 10):
                for a, b in zip(points[:-1], points[1:]):
                    v, e = mpmath.quad(lambda d: f(d, side), [a, b], error=True, maxdegree=10)
                    total += v
                    error += e
        return lam / mpmath.pi * total, lam / mpmath.pi * error
