"""Mooring lines by MoorDyn (the ``moordyn`` package, MoorDyn-C 2.7), moved by our bodies and
wet by our sea.  numpy and moordyn only, no FMI.

Frames and signs (DESIGN.md; docs/moorings.md)
-----------------------------------------------
Global frame z up from the mean water level, as MoorDyn's.  Our body's attitude (φ, θ, ψ)
means R = Rz(ψ)·Ry(θ)·Rx(φ); MoorDyn's coupled-body angles (a, b, c) mean
R = Rx(a)·Ry(b)·Rz(c), so they are computed from our R (``moordyn_angles``):
b = asin R₁₃, a = atan2(−R₂₃, R₃₃), c = atan2(−R₁₂, R₁₁).

The file's coupled objects, each on one of our bodies (``Coupling``):

- a coupled body (BODIES, ``Coupled``, 6 dof): MoorDyn's body reference point is our body's
  reference point; its ``BodyN`` points are in our body's axes from it.  MoorDyn gets
  x = (position, (a, b, c)) and ẋ = (velocity, (ȧ, ḃ, ċ)), the angle rates that turn the
  body at our ω (``moordyn_rates``: ω = ȧ·e_x + ḃ·Rx(a)·e_y + ċ·Rx(a)·Ry(b)·e_z); its load
  (force, moment about the reference point, global axes) is the load on our body;
- a coupled point (POINTS, ``Coupled``/``Vessel``/``Fairlead``, 3 dof, global coordinates):
  a point of our body at ``offset`` (body axes from the reference point): MoorDyn gets
  x = p + R·r and ẋ = v + ω × R·r; its force F gives our body F and the moment (R·r) × F.

Between two calls MoorDyn moves each coupled object from x with the constant rate ẋ (its own
time step dtM, as many as the step needs, the last one shorter): the points of a coupled
body follow its rotation to first order in the step.  MoorDyn also takes the angle rates
as the body's angular velocity for its points' velocities (v + ẋ_angles × R·r): exact in
yaw, off by O(roll, pitch)·ω·r otherwise (the lines' damping sees it, not their stretch).

One sea: MoorDyn runs with external water kinematics (WaveKin = 1, no waves or current of
its own).  Before each step [t, t + dt] every node and point MoorDyn asks for gets
u = u_current(z) + u_waves and a = a_waves, our current (``Env``: the profile, the current
inputs) and our waves (``WaveKinematics`` of the scene's components) at the step's midpoint
t + dt/2, held over the step; a node above the instantaneous surface (z > η) gets nothing, a
node resting on the sea bed (z < −h by its contact spring's penetration) the water just above
the bed.  MoorDyn's buoyancy keeps its still-water surface z = 0.

Tensions (MoorDyn's FairTen and AnchTen): the tension of the line's end segments, at its
end B (the fairlead) and end A (the anchor); the force on a fairlead also carries the
weight of the end node's half segment.
"""
from __future__ import annotations

import contextlib
import math
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .kinematics import rotation

# the OPTIONS every run has (the scene's rho, g and depth are added by the scene): the water's
# kinematics from hydrofmu (WaveKin 1), no output files nor time printing
RUN_OPTIONS = {"wavekin": 1, "disableoutput": 1, "disableouttime": 1}


class MooringError(RuntimeError):
    """MoorDyn refused the file or failed a step; ``log`` holds what MoorDyn printed."""

    def __init__(self, message, log=""):
        super().__init__(message)
        self.log = log


@dataclass(frozen=True)
class Coupling:
    """One coupled object of the MoorDyn file on our body ``body``: ``kind`` "body" (a
    coupled body, its ID ``id`` in BODIES) or "point" (a coupled point, ID in POINTS) at
    ``offset`` [m] (body axes from the body's reference point; points only)."""
    kind: str
    id: int
    body: str
    offset: tuple = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Layout:
    """What MoorDyn made of a file: the IDs of its coupled bodies and points (in MoorDyn's
    order of the coupled degrees of freedom), what hydrofmu cannot move ((kind, ID) of coupled
    pinned bodies and coupled rods), its line IDs, and its warnings (lines MoorDyn printed)."""
    bodies: tuple
    points: tuple
    unsupported: tuple
    lines: tuple
    dof: int
    warnings: tuple


@contextlib.contextmanager
def captured():
    """What the C library prints to stdout and stderr meanwhile, kept (``.text`` of the
    yielded object) instead of shown."""
    import sys

    class Out:
        text = ""
    out = Out()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as sink:
        try:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            yield out
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            out.text = sink.read().decode("utf-8", "replace")


def moordyn_angles(attitude) -> np.ndarray:
    """MoorDyn's coupled-body angles (a, b, c) [rad], R = Rx(a)·Ry(b)·Rz(c), of our attitude
    (φ, θ, ψ), R = Rz(ψ)·Ry(θ)·Rx(φ)."""
    r = rotation(attitude)
    return np.array([math.atan2(-r[1, 2], r[2, 2]), math.asin(min(1.0, max(-1.0, r[0, 2]))),
                     math.atan2(-r[0, 1], r[0, 0])])


def moordyn_rates(angles, omega) -> np.ndarray:
    """The rates (ȧ, ḃ, ċ) of MoorDyn's angles (a, b, c) that turn the body at ω [rad/s,
    global]: ω = ȧ·e_x + ḃ·Rx(a)·e_y + ċ·Rx(a)·Ry(b)·e_z."""
    a, b, _ = angles
    axes = np.array([[1.0, 0.0, math.sin(b)],
                     [0.0, math.cos(a), -math.sin(a) * math.cos(b)],
                     [0.0, math.sin(a), math.cos(a) * math.cos(b)]])
    return np.linalg.solve(axes, np.asarray(omega, dtype=float))


def _messages(text, level):
    """MoorDyn's messages of ``level`` ('WRN', 'ERR'), each with the lines that continue it (up to
    a blank or indented line, another message, or its summary of what it made)."""
    out, current = [], None
    for line in text.splitlines():
        if line.startswith(level):
            current = [line.strip()]
            out.append(current)
        elif current is not None and line.strip() and not line[0].isspace() \
                and not line.startswith(("ERR", "WRN", "MSG", "DBG", "Generated entities")):
            current.append(line.strip())
        else:
            current = None
    return tuple(" ".join(m) for m in out)


def _create(path):
    """(MoorDyn instance, printed text, the file's folder left out: messages name the file
    alone); MooringError with MoorDyn's messages if it fails."""
    import moordyn
    with captured() as out:
        try:
            md = moordyn.Create(str(path))
        except RuntimeError:
            md = None
    text = out.text.replace(str(Path(path).parent) + os.sep, "")
    if md is None:
        errors = [line for line in text.splitlines() if line.strip() and not line.startswith(" ")]
        start = next((i for i, line in enumerate(errors) if line.startswith("ERR")), None)
        raise MooringError("\n".join(errors[start:] if start is not None else errors[-3:]), text)
    return md, text


def _objects(md):
    """Layout of an instance (MoorDyn's order: coupled bodies, rods, points)."""
    import moordyn
    bodies, points, unsupported = [], [], []
    for i in range(1, moordyn.GetNumberBodies(md) + 1):
        body = moordyn.GetBody(md, i)
        kind = moordyn.GetBodyType(body)
        if kind == moordyn.BODY_TYPE_COUPLED:
            bodies.append(moordyn.GetBodyID(body))
        elif kind not in (moordyn.BODY_TYPE_FREE, moordyn.BODY_TYPE_FIXED):
            unsupported.append(("body", moordyn.GetBodyID(body)))
    for i in range(1, moordyn.GetNumberRods(md) + 1):
        rod = moordyn.GetRod(md, i)
        if moordyn.GetRodType(rod) in (moordyn.ROD_TYPE_COUPLED, moordyn.ROD_TYPE_CPLDPIN):
            unsupported.append(("rod", moordyn.GetRodID(rod)))
    for i in range(1, moordyn.GetNumberPoints(md) + 1):
        point = moordyn.GetPoint(md, i)
        if moordyn.GetPointType(point) == moordyn.POINT_TYPE_COUPLED:
            points.append(moordyn.GetPointID(point))
    lines = tuple(moordyn.GetLineID(moordyn.GetLine(md, i)) for i in range(1, moordyn.GetNumberLines(md) + 1))
    return tuple(bodies), tuple(points), tuple(unsupported), lines, moordyn.NCoupledDOF(md)


def inspect(text: str, filename: str = "lines.dat") -> Layout:
    """MoorDyn's reading of the input ``text`` (run as ``filename`` in a private folder):
    its coupled objects and lines; MooringError with MoorDyn's messages if it refuses it."""
    import moordyn
    folder = Path(tempfile.mkdtemp(prefix="hydrofmu-moordyn-"))
    try:
        path = folder / filename
        path.write_text(text, encoding="utf-8")
        md, said = _create(path)
        try:
            layout = _objects(md)
        finally:
            moordyn.Close(md)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return Layout(*layout, warnings=_messages(said, "WRN"))


class Mooring:
    """The mooring lines of one MoorDyn file on our bodies (module docstring).

    ``text``: the MoorDyn input as hydrofmu runs it (decks.moordyn.runnable with RUN_OPTIONS
    and the scene's rho, g, WtrDpth); ``couplings``: one per coupled object of the file;
    ``kinematics`` (wave_kinematics.WaveKinematics) and ``phasors`` (waves.Phasors, owned by
    this object) of the scene's waves, or None: no waves; ``filename``: the name MoorDyn's
    messages give the file.  The run's files are in ``workdir`` (removed by ``close``).

    ``start(t, motions, env)`` computes MoorDyn's initial equilibrium (its IC generation) with
    the bodies at their poses and returns the loads; ``step(t, dt, motions, env)`` advances the
    lines over [t, t + dt] and returns the loads at t + dt: {body: (6,) [N, N·m]}, on the body,
    global axes, moments about its reference point where MoorDyn moved it (x + dt·ẋ).
    ``motions``: {body: state.Motion} at t.
    """

    def __init__(self, text: str, couplings, kinematics=None, phasors=None, filename: str = "lines.dat"):
        import moordyn
        self.workdir = Path(tempfile.mkdtemp(prefix="hydrofmu-moordyn-"))
        self.kinematics, self.phasors = kinematics, phasors
        path = self.workdir / filename
        path.write_text(text, encoding="utf-8")
        try:
            self.md, self.log = _create(path)
        except MooringError:
            shutil.rmtree(self.workdir, ignore_errors=True)
            raise
        bodies, points, unsupported, self.line_ids, dof = _objects(self.md)
        by_key = {(c.kind, c.id): c for c in couplings}
        wanted = [("body", i) for i in bodies] + [("point", i) for i in points]
        missing = [f"{k.capitalize()}{i}" for k, i in wanted if (k, i) not in by_key]
        extra = [f"{c.kind.capitalize()}{c.id}" for c in couplings if (c.kind, c.id) not in wanted]
        if unsupported or missing or extra or dof != 6 * len(bodies) + 3 * len(points):
            self.close()
            raise MooringError(f"couplings do not match the file: unsupported {unsupported}, without a body "
                               f"{missing}, not coupled in the file {extra}")
        self.couplings = [by_key[w] for w in wanted]
        self.bodies = list(dict.fromkeys(c.body for c in self.couplings))
        self.lines = [moordyn.GetLine(self.md, i) for i in range(1, len(self.line_ids) + 1)]
        self.depth = math.inf if kinematics is None else kinematics.depth
        self.t = math.nan

    # -- the coupled objects' motion and loads
    def _pack(self, motions):
        x, xd = [], []
        for c in self.couplings:
            m = motions[c.body]
            p, v, w = (np.asarray(a, dtype=float) for a in (m.position, m.velocity[:3], m.velocity[3:6]))
            if c.kind == "body":
                angles = moordyn_angles(m.attitude)
                x += [*p, *angles]
                xd += [*v, *moordyn_rates(angles, w)]
            else:
                arm = rotation(m.attitude) @ np.asarray(c.offset, dtype=float)
                x += [*(p + arm)]
                xd += [*(v + np.cross(w, arm))]
        return x, xd

    def _loads(self, f, motions, dt=0.0):
        """Our bodies' loads of MoorDyn's forces ``f``, after MoorDyn moved the coupled objects
        over ``dt`` from ``motions``: a coupled point's moment about the reference point moved
        alike (its arm R·r advanced by dt·ω × R·r, as MoorDyn moved the point)."""
        out = {b: np.zeros(6) for b in self.bodies}
        f = np.asarray(f, dtype=float)
        k = 0
        for c in self.couplings:
            if c.kind == "body":
                out[c.body] += f[k:k + 6]
                k += 6
            else:
                m = motions[c.body]
                arm = rotation(m.attitude) @ np.asarray(c.offset, dtype=float)
                arm = arm + dt * np.cross(np.asarray(m.velocity[3:6], dtype=float), arm)
                out[c.body][:3] += f[k:k + 3]
                out[c.body][3:] += np.cross(arm, f[k:k + 3])
                k += 3
        if not all(np.all(np.isfinite(v)) for v in out.values()):
            raise MooringError("MoorDyn returned non-finite loads (its time step dtM too large for the lines?)")
        return out

    # -- the water MoorDyn's nodes feel
    def water(self, t: float, env):
        """(points (P, 3), u (P, 3) [m/s], a (P, 3) [m/s²]): our current and waves at time t at
        the points MoorDyn asks for (module docstring)."""
        import moordyn
        pts = np.array(moordyn.ExternalWaveKinGetCoordinates(self.md), dtype=float).reshape(-1, 3)
        u, a = np.zeros_like(pts), np.zeros_like(pts)
        eta = np.zeros(len(pts))
        at = pts.copy()
        at[:, 2] = np.maximum(at[:, 2], -self.depth)   # a node on the bed feels the water above it
        if self.kinematics is not None:
            rows = self.kinematics.at(self.phasors.at(t), self.phasors.ramp_factor, at)
            u, a, eta = rows[:, 0:3].copy(), rows[:, 3:6].copy(), rows[:, 7]
        wet = at[:, 2] <= eta
        if env is not None:
            for i in np.flatnonzero(wet):
                u[i] += env.current_at(at[i, 2])
        u[~wet] = 0.0
        a[~wet] = 0.0
        return pts, u, a

    def _set_water(self, t, env):
        import moordyn
        _, u, a = self.water(t, env)
        if len(u):
            moordyn.ExternalWaveKinSet(self.md, u.tolist(), a.tolist(), t)

    # -- time
    def start(self, t: float, motions: dict, env=None) -> dict:
        """MoorDyn's initial equilibrium (its IC generation, in still water) with the bodies held
        at the poses of ``motions`` (their velocities count from the first step); the loads then.  ``init_log``: what MoorDyn said of it."""
        import moordyn
        x, xd = self._pack(motions)
        with captured() as out:   # at rest: MoorDyn would move the bodies by their velocities meanwhile
            err = moordyn.Init(self.md, x, [0.0] * len(xd))
        self.init_log = out.text
        if err != 0:
            raise MooringError(f"MoorDyn's initialisation failed (error {err})", out.text)
        moordyn.SetVerbosity(self.md, moordyn.LEVEL_ERR)
        moordyn.ExternalWaveKinInit(self.md)
        self._set_water(t, env)
        self.t = t
        return self._loads(moordyn.Step(self.md, x, xd, t, 0.0), motions)

    def step(self, t: float, dt: float, motions: dict, env=None) -> dict:
        """The lines over [t, t + dt] with the bodies' ``motions`` at t; the loads at t + dt."""
        import moordyn
        x, xd = self._pack(motions)
        self._set_water(t + 0.5 * dt, env)
        try:
            f = moordyn.Step(self.md, x, xd, t, dt)
        except RuntimeError as exc:
            raise MooringError(f"MoorDyn's step at t = {t:g} s failed: {exc}") from None
        self.t = t + dt
        return self._loads(f, motions, dt)

    # -- outputs
    def tensions(self) -> tuple[np.ndarray, np.ndarray]:
        """(fairlead, anchor) tension of each line [N], in ``line_ids`` order (module docstring)."""
        import moordyn
        fair = np.array([moordyn.GetLineFairTen(line) for line in self.lines])
        anchor = np.array([np.linalg.norm(moordyn.GetLineNodeTen(line, 0)) for line in self.lines])
        return fair, anchor

    def nodes(self) -> list[np.ndarray]:
        """The node positions (n + 1, 3) [m] of each line, from end A (anchor) to end B."""
        import moordyn
        return [np.array([moordyn.GetLineNodePos(line, i) for i in range(moordyn.GetLineNumberNodes(line))])
                for line in self.lines]

    # -- FMU state
    def state(self) -> dict:
        """The whole state (MoorDyn's serialized lines, our phasors, the time)."""
        import moordyn
        return {"moordyn": bytes(moordyn.Serialize(self.md)), "t": self.t,
                "phasors": self.phasors.state() if self.phasors is not None else None}

    def set_state(self, state: dict):
        import moordyn
        moordyn.Deserialize(self.md, state["moordyn"])
        self.t = state["t"]
        if self.phasors is not None:
            self.phasors.set_state(state["phasors"])

    def close(self):
        import moordyn
        md, self.md = getattr(self, "md", None), None
        if md is not None:
            moordyn.Close(md)
        shutil.rmtree(self.workdir, ignore_errors=True)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
