"""Types of the public names, which ``__init__.py`` imports lazily."""
__version__: str
__all__ = [
    'BallJoint', 'BodyLoads', 'Convolution', 'CoupledBodies', 'Coupling', 'CurrentPolar', 'Env',
    'InputError', 'LumpedBody', 'Motion', 'Result', 'RigidBody', 'Scene', 'StateSpace',
    'Tuning', 'ViscousDrag', '__version__', 'build', 'load_scene', 'read_csv', 'read_parquet', 'run', 'run_files', 'tune',
]

from .api import build, load_scene, run, run_files
from .cosim.result import Result, read_csv
from .cosim.stream import read_parquet
from .errors import InputError
from .physics.coupling import Coupling
from .physics.current_polar import CurrentPolar
from .physics.joint import BallJoint
from .physics.loads import BodyLoads
from .physics.lumped import LumpedBody
from .physics.memory import Convolution, StateSpace
from .physics.rigid_body import CoupledBodies, RigidBody
from .physics.state import Env, Motion
from .physics.viscous_drag import ViscousDrag
from .scene import Scene
from .tuning import Tuning, tune
