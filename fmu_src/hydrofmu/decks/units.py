"""Unit systems of SIMO and RIFLEX input files, and the check of what a file declares.

hydrofmu computes in SI (kg, N, m, s).  A SIMO or RIFLEX file may use another consistent
system; the scene says which one with ``units`` (default "SI"), and the reader converts
each value by its dimension: a mass [M] (and M·L, M·L²) times ``mass``, a force [F] (and
F/L, F·T, F·L, F/(L/T)²) times ``force``; lengths and times are m and s in every system.

    system    mass unit   force unit   mass   force
    "SI"      kg          N            1      1
    "Mg-kN"   Mg (t)      kN           1000   1000
    "kg-kN"   kg          kN           1      1000     (RIFLEX's default unit names)

A file that declares its units is checked against the scene's choice, so a wrong choice is
one error, never a silent factor of 1000:

- SIMO, ``SYSTem DESCription SIMO``: the line ``LENUNI TIMUNI MASUNI GRAV RHOW …``
  (defaults m, s, Mg, 9.81, 1.025).  MASUNI kg → "SI", Mg/t/tonne → "Mg-kN"; RHOW must fit
  MASUNI (about 1025 for kg, about 1.025 for Mg), LENUNI m, TIMUNI s.
- RIFLEX, ``UNIT NAMe SPECification``: the line ``UT UL UM UF GRAV GCONS`` (defaults
  s, m, kg, kN, 9.81, 0.001).  UM and UF give the system; GCONS must equal mass/force of
  it (1 for kg-N and Mg-kN, 0.001 for kg-kN), UT s, UL m.
"""
from dataclasses import dataclass

from .lines import fields

SYSTEMS = {"SI": (1.0, 1.0), "Mg-kN": (1000.0, 1000.0), "kg-kN": (1.0, 1000.0)}
MASS = {"KG": 1.0, "MG": 1000.0, "T": 1000.0, "TONNE": 1000.0, "TON": 1000.0}
FORCE = {"N": 1.0, "KN": 1000.0}
# names a units line may hold (supported or not: an unsupported one is an error, not text)
UNIT_NAMES = {*MASS, *FORCE, "M", "S", "MM", "CM", "KM", "FT", "IN", "SEC", "MIN", "H", "LB", "G"}


@dataclass(frozen=True)
class Declared:
    """What a file declares: ``system`` (a key of SYSTEMS) on ``line`` (a lines.Line),
    found in ``field`` (the name to give in an error)."""
    system: str
    line: object
    field: str


def factors(system):
    """(mass factor, force factor) to SI for a system name."""
    return SYSTEMS[system]


def check(declared, system, path, key="units"):
    """Error (at the declaration) when a file declares another system than the scene's;
    ``key``: the scene key that names it."""
    if declared is not None and declared.system != system:
        raise declared.line.error(declared.field, f"the file declares {declared.system} units but the scene reads "
                                                  f"{path} as {system}: set {key} = \"{declared.system}\" for this "
                                                  f"file in the scene (or correct the file)")


def _name(line, field, value, table, what):
    key = str(value).upper()
    if key not in table:
        raise line.error(field, f"unsupported {what} unit {value!r} (hydrofmu reads {', '.join(SYSTEMS)}: "
                                f"mass kg or Mg, force N or kN, length m, time s)")
    return table[key]


def _plain(line, field, value, want):
    if str(value).lower() != want:
        raise line.error(field, f"unsupported unit {value!r}: hydrofmu reads files in {want}")


def simo_units(line):
    """Declared system of a SIMO ``LENUNI TIMUNI MASUNI GRAV RHOW …`` line."""
    names = ["LENUNI", "TIMUNI", "MASUNI", "GRAV", "RHOW", "RHOA", "WAKIVI", "AIRKIVI"]
    v = fields(line, names, kind=[str] * 3 + [float] * 5,
               defaults={"LENUNI": "m", "TIMUNI": "s", "MASUNI": "Mg", "GRAV": 9.81, "RHOW": 1.025,
                         "RHOA": 0.00125, "WAKIVI": 1.188e-6, "AIRKIVI": 1.516e-5})
    _plain(line, "LENUNI", v["LENUNI"], "m")
    _plain(line, "TIMUNI", v["TIMUNI"], "s")
    mass = _name(line, "MASUNI", v["MASUNI"], MASS, "mass")
    rhow = 1025.0 / mass
    if not 0.9 * rhow <= v["RHOW"] <= 1.1 * rhow:
        raise line.error("RHOW", f"water density {v['RHOW']:g} does not fit MASUNI = {v['MASUNI']} "
                                 f"(about {rhow:g} expected): the file's units are not what it declares")
    return Declared("SI" if mass == 1.0 else "Mg-kN", line, "MASUNI")


def riflex_units(line):
    """Declared system of a RIFLEX ``UT UL UM UF GRAV GCONS`` line."""
    names = ["UT", "UL", "UM", "UF", "GRAV", "GCONS"]
    v = fields(line, names, kind=[str] * 4 + [float] * 2,
               defaults={"UT": "s", "UL": "m", "UM": "kg", "UF": "kN", "GRAV": 9.81, "GCONS": 0.001})
    _plain(line, "UT", v["UT"], "s")
    _plain(line, "UL", v["UL"], "m")
    mass = _name(line, "UM", v["UM"], MASS, "mass")
    force = _name(line, "UF", v["UF"], FORCE, "force")
    system = next((k for k, f in SYSTEMS.items() if f == (mass, force)), None)
    if system is None:
        raise line.error("UF", f"unsupported unit pair UM = {v['UM']}, UF = {v['UF']} "
                               f"(hydrofmu reads {', '.join(SYSTEMS)})")
    if abs(v["GCONS"] - mass / force) > 1e-6 * (mass / force):
        raise line.error("GCONS", f"GCONS = {v['GCONS']:g} does not fit UM = {v['UM']}, UF = {v['UF']} "
                                  f"(expected {mass / force:g})")
    return Declared(system, line, "UM")

