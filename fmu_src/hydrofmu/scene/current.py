"""The current of ``[environment]``: uniform, an inline profile, or a vendor current deck."""
from .. import admissible, keys
from ..errors import InputError
from .problems import deck_path


CURRENT_FORMATS = ("deeplines", "sima", "riflex")
# keys that go with current_deck; the last three only with current_format = "riflex"
CURRENT_DECK_KEYS = tuple(keys.CURRENT_DECK)


def read_current(problems, env):
    """(surface speed, surface direction, profile rows or None) of ``[environment]``: a uniform
    current (current_speed, current_direction), an inline ``current_profile`` of
    [z, speed, direction] rows, or a ``current_deck`` read by its ``current_format``."""
    from ..physics.current import CurrentProfile, profile_problem
    given = [k for k in ("current_profile", "current_deck") if k in env]
    loose = [k for k in CURRENT_DECK_KEYS if k in env]
    if loose and "current_deck" not in env:
        problems.add(f"environment.{loose[0]}", "goes with current_deck (the file the current is read from)")
        return None, None, None
    uniform = [k for k in ("current_speed", "current_direction") if k in env]
    if len(given) > 1 or (given and uniform):
        problems.add(f"environment.{(given + uniform)[1]}", "give the current once: current_speed/current_direction "
                                                            "(uniform), current_profile or current_deck")
        return None, None, None
    if not given:
        speed = problems.number(env, "current_speed", "environment.current_speed", 0.0, nonneg=True)
        direction = problems.number(env, "current_direction", "environment.current_direction", 0.0)
        if direction is not None and admissible.odd_direction(direction):
            problems.warn("environment.current_direction", admissible.odd_direction(direction))
        return speed, direction, None
    if "current_deck" in env:
        rows = _current_deck(problems, env)
    else:
        rows = _profile_rows(problems, env["current_profile"], "environment.current_profile")
        if rows is not None:
            problem = profile_problem(*zip(*rows))
            if problem is not None:
                k, name, message = problem
                problems.add(f"environment.current_profile[{k}]", f"{name}: {message}")
                rows = None
    if rows is None:
        return None, None, None
    for k, row in enumerate(rows if "current_profile" in env else ()):
        if admissible.odd_direction(row[2]):
            problems.warn(f"environment.current_profile[{k}]", admissible.odd_direction(row[2]))
    profile = CurrentProfile.from_rows(rows)
    return profile.surface_speed, profile.surface_direction, [list(r) for r in rows]


def _profile_rows(problems, raw, where):
    """[[z, speed, direction], ...] from the scene, or None after recording one problem."""
    if not isinstance(raw, list) or not raw:
        problems.add(where, "expected rows [z, speed, direction] (z m up from the mean free surface, "
                            "speed m/s, direction deg going to)")
        return None
    for k, row in enumerate(raw):
        if not isinstance(row, list) or len(row) != 3:
            n = len(row) if isinstance(row, list) else 1
            problems.add(f"{where}[{k}]", f"{'missing value' if n < 3 else 'too many values'}: expected "
                                          f"[z, speed, direction], found {row!r}")
            return None
        for name, v in zip(("z", "speed", "direction"), row):
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                problems.add(f"{where}[{k}]", f"{name}: expected a number, found {v!r}")
                return None
    return [[float(v) for v in row] for row in raw]


def _current_deck(problems, env):
    """Profile rows from a vendor file: DeepLines *CURRENT/*CURPROF, a SIMA (SIMO/RIFLEX)
    current profile file, or a current state of a RIFLEX INPMOD file's environment; deck
    errors are recorded with their file, line and field."""
    from ..decks.deeplines import read_current_profile
    from ..decks.simo import read_current_profile as read_sima
    fmt = problems.choice(env, "current_format", "environment.current_format", CURRENT_FORMATS)
    path = deck_path(problems, env, "environment", "current_deck")
    riflex_only = [k for k in CURRENT_DECK_KEYS[1:] if k in env]
    if fmt is not None and fmt != "riflex" and riflex_only:
        problems.add(f"environment.{riflex_only[0]}", 'only for current_format = "riflex" (an INPMOD file '
                                                     'holds several environments and current states)')
        return None
    if fmt is None or path is None:
        return None
    if fmt == "riflex":
        return _riflex_current(problems, env, path)
    try:
        return problems.read((read_current_profile if fmt == "deeplines" else read_sima)(path))
    except InputError as exc:
        problems.add("environment.current_deck", str(exc))
        return None


def _riflex_current(problems, env, path):
    """The profile of one ``NEW CURRENT STATE`` of a RIFLEX INPMOD file: the environment
    ``current_environment`` (IDENV) and state ``current_state`` (ICUSTA), each optional
    when the file has only one; ``current_units`` checked against the file's units line."""
    from ..decks.riflex import read_current_states
    from ..decks.units import SYSTEMS
    units = None
    if "current_units" in env:
        units = problems.choice(env, "current_units", "environment.current_units", tuple(SYSTEMS))
        if units is None:
            return None
    found = problems.deck(path, "environment.current_deck", read_current_states, units)
    if found is None:
        return None
    envs = {k: v for k, v in found.items() if v}
    name = env.get("current_environment")
    if name is None:
        if len(envs) != 1:
            problems.add("environment.current_environment",
                         f"{path.name} has {len(envs)} environments with a NEW CURRENT STATE"
                         f"{' (' + ', '.join(envs) + '): name one' if envs else ''}")
            return None
        name = next(iter(envs))
    elif not isinstance(name, str) or name not in envs:
        problems.add("environment.current_environment",
                     f"{name!r} is not an environment with a NEW CURRENT STATE in {path.name} "
                     f"(it has: {', '.join(envs) or 'none'})")
        return None
    states = envs[name]
    number = env.get("current_state")
    if number is None:
        if len(states) != 1:
            problems.add("environment.current_state", f"environment {name!r} of {path.name} has {len(states)} "
                                                      f"current states ({', '.join(map(str, states))}): name one")
            return None
        number = next(iter(states))
    elif not isinstance(number, int) or isinstance(number, bool) or number not in states:
        problems.add("environment.current_state", f"{number!r} is not a current state of environment {name!r} "
                                                  f"in {path.name} (it has: {', '.join(map(str, states))})")
        return None
    return [list(r) for r in states[number].rows]
