"""The typed description of an FMU: what the build writes into its resources and its slave reads.

One dataclass per FMU kind (``LoadFMU``, ``ConnectorFMU``, ``DynamicsFMU``) with nested ones
for the environment, effects, couplings, joints and bodies.  ``hydrofmu.assembly`` produces
them from a scene, ``fmi.build`` writes them with ``dump`` and the slaves read them back with
``read``: both sides use these classes, so they agree by construction.  The JSON form follows
the type hints (arrays as nested lists, nested dataclasses as tables), nothing else.

Units and frames are the scene's (SI, global axes, loads about the body's reference point).
This module needs numpy only (with the coupling kernels it builds): the FMU runtime imports
it at instantiation.
"""
from __future__ import annotations

import json
import math
import types
import typing
from dataclasses import dataclass, field, fields, is_dataclass
from pathlib import Path

import numpy as np

from .physics.coupling import Coupling
from .physics.memory import Realisation

FILE = "hydrofmu.json"   # the description's name in the FMU's resources


@dataclass
class Environment:
    """Water density rho [kg/m³], gravity g [m/s²], uniform current (speed [m/s], 'going to'
    direction [deg] counter-clockwise from global +x): start values of the FMU's variables."""
    rho: float
    g: float
    current_speed: float
    current_direction: float
    current_profile: np.ndarray | None = None   # rows [z m, speed m/s, direction deg]; None: uniform


@dataclass
class Effect:
    """One load model on one body: ``type`` (see scene.EFFECT_TYPES), unique ``name`` and the
    data its kernel needs (plain JSON-able values, decks already read; physics.loads.make_effect)."""
    type: str
    name: str
    data: dict


@dataclass
class Kernel:
    """Retardation kernel of one element: samples at s = 0, TIMDEL, … [N·s/m, N·s, N·m·s]
    coupling dof ``dof_a`` of body A with dof ``dof_b`` of body B (1-based IDOF_A, IDOF_B)."""
    dof_a: int
    dof_b: int
    values: np.ndarray


@dataclass
class Fit:
    """A stored state-space realisation h(t) ≈ C·exp(A·t)·B of kernel (dof_a, dof_b), as
    physics.memory.Realisation holds it (block-diagonal A, normalised RMS ``error``)."""
    dof_a: int
    dof_b: int
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    error: float


@dataclass
class HydroCoupling:
    """A SIMO hydrodynamic coupling between scene bodies ``a`` and ``b`` (a == b: the body's
    own radiation memory), from plain arrays: ``added_mass`` A∞ (6×6, row dof of a, column dof
    of b), ``timdel`` [s] (None without kernels) and ``kernels``.  Memory evaluator:
    ``method`` 'convolution' | 'state_space' (with ``tolerance`` or ``order``);
    ``memory_length`` [s] truncates the kernels; ``set``: the knobs the scene sets itself.
    ``fits``: state-space realisations stored at build time (empty: fitted when needed)."""
    name: str
    a: str
    b: str
    added_mass: np.ndarray
    timdel: float | None
    kernels: list[Kernel]
    method: str = "convolution"
    tolerance: float = 0.01
    order: int | None = None
    memory_length: float | None = None
    set: list[str] = field(default_factory=list)
    fits: list[Fit] = field(default_factory=list)
    # the BEM result it comes from (bem.BemCouplings), for the build's report: not in the FMU
    bem: object = field(default=None, compare=False, repr=False, metadata={"resources": False})

    def model(self, v0_a=None, v0_b=None):
        """The physics.coupling.Coupling of this coupling with its evaluator settings
        (v0_a, v0_b: the bodies' velocities at the start)."""
        return Coupling(self.added_mass, self.timdel, {(k.dof_a, k.dof_b): k.values for k in self.kernels},
                        self.method, self.tolerance, self.order, self.memory_length, v0_a=v0_a, v0_b=v0_b,
                        own=self.a == self.b, name=self.name, bodies=(self.a, self.b),
                        fits={(f.dof_a, f.dof_b): Realisation(f.A, f.B, f.C, f.error) for f in self.fits} or None)


@dataclass
class CouplingSide:
    """One side of a coupling as a load FMU applies it: 'A' is the load on body a from b's
    motion (A∞), 'B' the load on b from a's motion (A∞ᵀ); ``source``: the driving body.
    ``velocity``: the source's velocity at t = 0, start of the ``<source>.velocity`` inputs
    (None for the body's own radiation, which reads the body's own velocity input)."""
    coupling: HydroCoupling
    side: str
    velocity: np.ndarray | None = None

    @property
    def name(self) -> str:
        return self.coupling.name

    @property
    def own(self) -> bool:
        """The body's own radiation (self-coupling): driven by its own motion."""
        return self.coupling.a == self.coupling.b

    @property
    def source(self) -> str:
        return self.coupling.b if self.side == "A" else self.coupling.a

    @property
    def mass(self) -> np.ndarray:
        """6×6 block of this side: load = −mass·a_source."""
        return self.coupling.added_mass if self.side == "A" else self.coupling.added_mass.T


@dataclass
class Waves:
    """The scene's wave field as one body's FMU sees it (physics.waves): the sea state
    ``spectrum`` and its knobs ``sea`` (SeaState fields: start values of the ``waves.*``
    parameters), the frequency ``window`` [rad/s] common to every body of the scene (so
    that all draw the same components; None: no excitation in the scene, the whole spectrum),
    and, with an excitation effect ``name`` (outputs ``<name>.force``, ``<name>.elevation``; None:
    none on this body), this body's transfer function per unit amplitude: ``omega`` [rad/s],
    ``directions`` [deg], ``re`` + i·``im`` (nω, nβ, 6) [N/m, N·m/m], e^{+iωt}, referred to the
    global origin; ``position`` (x, y) [m] its mean position.  ``kinematics``: an effect of
    this FMU feels the incident-wave kinematics (physics/wave_kinematics.py); ``points``: the
    named points whose kinematics it outputs, {name: {"position": global (3)} or {"offset":
    body axes (3)}}."""
    name: str | None
    spectrum: str
    sea: dict
    window: list[float] | None
    omega: np.ndarray | None = None
    directions: np.ndarray | None = None
    re: np.ndarray | None = None
    im: np.ndarray | None = None
    position: np.ndarray | None = None
    kinematics: bool = False
    points: dict = field(default_factory=dict)

    def sea_state(self, **knobs):
        from .physics.waves import SeaState
        return SeaState(self.spectrum, **{**self.sea, **knobs})

    def transfer(self, g, depth):
        """The body's TransferFunction, or None (no excitation on this body)."""
        from .physics.waves import TransferFunction
        if self.name is None:
            return None
        return TransferFunction(self.omega, self.directions, self.re + 1j * self.im, self.position, g, depth)


@dataclass
class Drift:
    """A body's second-order wave drift (physics.drift) on the scene's wave field (the same
    components as its ``Waves``): effect ``name`` (output ``<name>.force``), ``method``
    mean | newman | qtf, ``cutoff`` [rad/s] (qtf: the largest |ω_i − ω_j| kept; inf: all),
    ``omega`` [rad/s]; mean drift data: ``directions`` [deg] and ``values`` (nω, nβ, 6)
    [N/m², N·m/m²]; QTF data: ``pairs`` (nP, 2) [deg] and ``re`` + i·``im`` (nω, nω, nP, 6),
    referred to the global origin; ``position`` (x, y) [m] the body's mean position."""
    name: str
    method: str
    cutoff: float
    omega: np.ndarray
    position: np.ndarray
    directions: np.ndarray | None = None
    values: np.ndarray | None = None
    pairs: np.ndarray | None = None
    re: np.ndarray | None = None
    im: np.ndarray | None = None

    @classmethod
    def of(cls, effect: Effect, position) -> "Drift":
        """The Drift of a scene body's ``wave_drift`` effect, the body at ``position`` [m]."""
        dat = effect.data
        arr = {k: (np.array(dat[k], float) if k in dat else None) for k in ("directions", "values", "pairs", "re", "im")}
        return cls(effect.name, dat["method"], float(dat["cutoff"]), np.array(dat["omega"], float),
                   np.array(position[:2], float), **arr)

    def data(self, g, depth):
        """physics.drift.QTF or MeanDrift of this body."""
        from .physics.drift import QTF, MeanDrift
        if self.pairs is not None:
            return QTF(self.omega, [tuple(p) for p in self.pairs], self.re + 1j * self.im, self.position, g, depth)
        return MeanDrift(self.omega, self.directions, self.values)

    def kernel(self, comps, g, depth):
        """physics.drift.DriftLoad of the components ``comps``."""
        from .physics.drift import DriftLoad
        return DriftLoad(self.method, comps, self.data(g, depth), self.cutoff, self.position, g, depth)

    def c_params(self):
        """drift.c's record after the output: [method (0 mean, 1 newman, 2 qtf), cutoff (−1: none),
        x, y, the data's c_params] (the wave numbers are drift.c's, from g and depth at
        initialization)."""
        from .physics.drift import METHODS
        return ([float(METHODS.index(self.method)), self.cutoff if math.isfinite(self.cutoff) else -1.0]
                + self.position.tolist() + self.data(9.81, math.inf).c_params())


@dataclass
class LoadFMU:
    """Hydrodynamic loads on one body: its effects and coupling sides.  ``position``,
    ``attitude``, ``velocity``: the reference point's state at t = 0 (the motion inputs'
    start values); ``accel_mode``: 'export' | 'explicit' (acceleration loads exported as
    mass or applied as −M·a)."""
    description: str
    body: str
    position: np.ndarray
    attitude: np.ndarray
    accel_mode: str
    effects: list[Effect]
    couplings: list[CouplingSide]
    environment: Environment
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(6))
    waves: Waves | None = None
    drift: Drift | None = None


@dataclass
class Pose:
    """State at t = 0 of a reference point: position [m], attitude (roll, pitch, yaw) [rad]
    and velocity (linear [m/s], angular [rad/s], global axes)."""
    position: np.ndarray
    attitude: np.ndarray
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(6))


@dataclass
class JointSpring:
    """physics.joint.BallJoint parameters: joint points (A's body axes; B's body axes, or
    global for the earth), spring–dampers k_lin [N/m], c_lin [N·s/m], k_rot [N·m/rad],
    c_rot [N·m·s/rad], ``free`` axes (about A's x, y, z) and r_rel0 = R_Aᵀ·R_B at the start."""
    point_a: np.ndarray
    point_b: np.ndarray
    k_lin: float
    c_lin: float
    k_rot: float
    c_rot: float
    free: list[bool]
    r_rel0: np.ndarray


@dataclass
class ConnectorFMU:
    """RIFLEX CONB ball joint ``name`` between side ``a`` and side ``b`` (None: the earth);
    ``node``: the joint's lumped properties (physics.lumped.LumpedBody keywords)."""
    description: str
    name: str
    accel_mode: str
    node: dict
    joint: JointSpring
    a: Pose
    b: Pose | None
    environment: Environment
    waves: Waves | None = None   # the scene's waves, for the node's drag and inertia (kinematics only)


@dataclass
class DynamicsBody:
    """One body of a dynamics FMU: mass [kg], inertia [kg·m²] about the CoG in body axes, cog
    [m] from the reference point (body axes), stiffness and damping (6×6, global, about the
    reference point), initial pose and velocity, exported ``added_mass`` (6×6), the
    ``load_sources`` it sums ('' : its load FMU, else a joint's name) and ``loads``: each
    source's load at t = 0, the start values of its load inputs (filled by
    ``fmi.starts.fill_loads`` from the source FMUs; empty: zero)."""
    name: str
    mass: float
    inertia: np.ndarray
    cog: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    position: np.ndarray
    attitude: np.ndarray
    velocity: np.ndarray
    load_sources: list[str]
    added_mass: np.ndarray
    loads: list[np.ndarray] = field(default_factory=list)

    @staticmethod
    def load_input(source: str) -> str:
        """The variable group of the load input from ``source`` (without the body prefix)."""
        return f"{source}.force" if source else "force"


@dataclass
class CrossMass:
    """Cross added mass in a dynamics group: load on ``target`` from ``source``'s acceleration."""
    target: str
    source: str
    mass: np.ndarray


@dataclass
class DynamicsFMU:
    """Rigid-body dynamics of one body or of a group coupled by cross added mass; RK4
    ``substep`` [s] bound, ``load_hold`` 'constant' | 'linear'."""
    description: str
    bodies: list[DynamicsBody]
    cross: list[CrossMass]
    substep: float
    load_hold: str


KINDS = {"load": LoadFMU, "connector": ConnectorFMU, "dynamics": DynamicsFMU}
Description = LoadFMU | ConnectorFMU | DynamicsFMU


def kind(desc: Description) -> str:
    return next(k for k, cls in KINDS.items() if isinstance(desc, cls))


def to_plain(obj):
    """JSON-able form: dataclasses as dicts of their fields, arrays as nested lists."""
    if is_dataclass(obj):
        return {f.name: to_plain(getattr(obj, f.name)) for f in fields(obj) if f.metadata.get("resources", True)}
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, (list, tuple)):
        return [to_plain(v) for v in obj]
    if isinstance(obj, dict):
        return {k: to_plain(v) for k, v in obj.items()}
    return obj


def from_plain(tp, value):
    """Inverse of ``to_plain`` for the type hint ``tp``."""
    if value is None:
        return None
    origin = typing.get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        tp = next(a for a in typing.get_args(tp) if a is not type(None))
        return from_plain(tp, value)
    if tp is np.ndarray:
        return np.asarray(value, dtype=float)
    if is_dataclass(tp):
        hints = _hints(tp)
        return tp(**{f.name: from_plain(hints[f.name], value[f.name]) for f in fields(tp) if f.name in value})
    if origin is list:
        (item,) = typing.get_args(tp)
        return [from_plain(item, v) for v in value]
    if tp is float:
        return float(value)
    return value


def _hints(tp) -> dict:
    """A dataclass's resolved field types.  The annotations are strings (postponed), evaluated
    in the class's own module namespace, taken from the class rather than from sys.modules:
    inside an FMU loaded into a running Python, a build in the same process may have taken
    this runtime's modules out of sys.modules, and typing.get_type_hints would then see an
    empty namespace (NameError on 'np')."""
    return typing.get_type_hints(tp, globalns=tp.__init__.__globals__)


def dumps(desc: Description) -> str:
    return json.dumps({"kind": kind(desc), **to_plain(desc)})


def loads(text: str) -> Description:
    plain = json.loads(text)
    return from_plain(KINDS[plain.pop("kind")], plain)


def write(desc: Description, folder) -> Path:
    """Write the description into an FMU's resources folder; returns the file."""
    path = Path(folder) / FILE
    path.write_text(dumps(desc))
    return path


def read(folder) -> Description:
    """The description in an FMU's resources folder."""
    return loads((Path(folder) / FILE).read_text())
