"""Cost of the wave phasors and of the incident-wave kinematics, per step, at 50, 200, 1000
components: ``bench --part kinematics`` (and the phasor figures of ``--part waves``).

Python flavour (numpy): the `waves` kernel (``physics.waves.WaveLoad``: the shared
``Phasors`` advanced + one (2N × 7) product) against the same with cos/sin of every component
at every step (the kernel before the phasors), and the kinematics at one point per step
(``WaveKinematics.at``: a fixed point, a point that moves, Wheeler stretching), each per point
against the `waves` kernel.  Compiled flavour: the same in C (physics/waves.c,
physics/wave_kinematics.c and the harness kinematics_bench.c beside this file, compiled here),
so the per-component cost is seen without the FMI or ctypes overhead.  Targets (issue 34):
≤ 5 ns per component per step compiled, ≤ 0.1 µs in the Python flavour.
"""
import ctypes
import math
from pathlib import Path

import numpy as np

from . import timing

COUNTS = (50, 200, 1000)
DT = 0.05
HERE = Path(__file__).resolve().parent


def _sea(n):
    from ..physics.waves import SeaState, components
    sea = SeaState("jonswap", hs=3.0, tp=9.0, components=n, seed=1, spreading=4.0)
    return sea, components(sea)


def _transfer(comps):
    """A smooth transfer function over the components' band (its values do not matter for the cost)."""
    from ..physics.waves import TransferFunction
    w = np.linspace(comps.omega.min() * 0.99, comps.omega.max() * 1.01, 40)
    d = np.arange(0.0, 360.0, 30.0)
    x = (1e5 * np.exp(-w[:, None, None]) * (1 + 0.1 * np.cos(np.radians(d))[None, :, None])
         * np.ones(6)[None, None, :]).astype(complex)
    return TransferFunction(w, d, x, (10.0, -5.0))


def python_costs(counts=COUNTS, calls=2000, rounds=5):
    """{n: {name: seconds per step}} of the Python kernels (see the module docstring)."""
    from ..physics.wave_kinematics import WaveKinematics
    from ..physics.waves import Phasors, WaveLoad, ramp
    out = {}
    for n in counts:
        _, comps = _sea(n)
        tf = _transfer(comps)

        def phasor_load():
            load = WaveLoad(comps, tf, (10.0, -5.0))
            return lambda k: load(DT * k)

        def trig_load():   # the kernel before the phasors: cos/sin of ω_k t every step
            base = WaveLoad(comps, tf, (10.0, -5.0))
            c = base.phasors.amplitude
            table = np.vstack((c[:, None] * (base.table[0::2] - 1j * base.table[1::2])))
            real = np.vstack((table.real, -table.imag))
            trig = np.empty(2 * n)

            def f(k):
                wt = comps.omega * (DT * k)
                np.cos(wt, out=trig[:n])
                np.sin(wt, out=trig[n:])
                return trig.dot(real) * ramp(DT * k, 0.0)
            return f

        def kin(stretching, moving):
            def make():
                ph = Phasors(comps)
                k_ = WaveKinematics(comps, 9.81, math.inf, stretching)
                fixed = np.array([[5.0, -3.0, -8.0]])

                def f(k):
                    p = ph.at(DT * k)
                    pt = fixed + (np.array([[0.5 * math.sin(0.3 * k * DT), 0.0, 0.3 * math.cos(0.4 * k * DT)]])
                                  if moving else 0.0)
                    return k_.at(p, 1.0, pt)
                return f
            return make

        def phasors_alone():
            ph = Phasors(comps)
            return lambda k: ph.at(DT * k)
        got = timing.per_call({"waves": phasor_load, "waves_trig": trig_load, "phasors": phasors_alone,
                               "kin_fixed": kin("none", False), "kin_moving": kin("none", True),
                               "kin_wheeler": kin("wheeler", False)}, calls, rounds)
        # a kinematics call advances the phasors too: its own cost is what is left
        for key in ("kin_fixed", "kin_moving", "kin_wheeler"):
            got[key] -= got["phasors"]
        out[n] = got
    return out


def _library():
    from ..cc import cached_many
    physics = HERE.parent / "physics"
    lib = ctypes.CDLL(str(cached_many([HERE / "kinematics_bench.c", physics / "waves.c", physics / "wave_kinematics.c"],
                                      "kinematics_bench", libs=["-lm"],
                                      flags=["-O3", "-shared", "-fPIC", "-std=gnu99"])))
    D, P = ctypes.c_double, ctypes.POINTER(ctypes.c_double)
    for name in ("hfb_waves", "hfb_trig", "hfb_phasors"):
        getattr(lib, name).restype = D
        getattr(lib, name).argtypes = [P, ctypes.c_int, D, P]
    lib.hfb_kin.restype = D
    lib.hfb_kin.argtypes = [P, P, ctypes.c_int, D, ctypes.c_int, P]
    lib.hf_kin_build.restype = P
    return lib


def compiled_costs(counts=COUNTS, steps=20000, rounds=5):
    """{n: {name: seconds per step}} of the C kernels, the best of ``rounds`` (each a tight C loop
    of ``steps`` steps: on a shared machine the least disturbed round is the kernel's cost)."""
    from ..physics.waves import STRETCHING
    lib = _library()
    D, P = ctypes.c_double, ctypes.POINTER(ctypes.c_double)
    out = {}
    for n in counts:
        sea, comps = _sea(n)
        tf = _transfer(comps)
        # the build's parameters as waves.c lays them out, from the Python kernel's table
        from ..physics.waves import WaveLoad
        load = WaveLoad(comps, tf, (10.0, -5.0))
        params = np.r_[n, 0.0, comps.omega, load.phasors.amplitude.view(float), load.table.ravel(), comps.direction]
        arr = params.ctypes.data_as(P)
        kin = {s: lib.hf_kin_build(comps.omega.ctypes.data_as(P), comps.direction.ctypes.data_as(P), n, D(9.81),
                                   D(math.inf), STRETCHING.index(s)) for s in ("none", "wheeler")}
        sink = D()
        runs = {"waves": lambda: lib.hfb_waves(arr, steps, DT, ctypes.byref(sink)),
                "waves_trig": lambda: lib.hfb_trig(arr, steps, DT, ctypes.byref(sink)),
                "phasors": lambda: lib.hfb_phasors(arr, steps, DT, ctypes.byref(sink)),
                "kin_fixed": lambda: lib.hfb_kin(arr, kin["none"], steps, DT, 0, ctypes.byref(sink)),
                "kin_moving": lambda: lib.hfb_kin(arr, kin["none"], steps, DT, 1, ctypes.byref(sink)),
                "kin_wheeler": lambda: lib.hfb_kin(arr, kin["wheeler"], steps, DT, 0, ctypes.byref(sink))}
        times = {k: [] for k in runs}
        for _ in range(rounds):
            for k, f in runs.items():
                times[k].append(f() / steps)
        out[n] = {k: float(np.min(v)) for k, v in times.items()}
        for p in kin.values():
            ctypes.CDLL(None).free(p)
    return out


def rows(python, compiled):
    """CSV rows: per flavour and component count, ns per component per step of the `waves`
    kernel (phasors) and of the cos/sin kernel, and each kinematics case per point per step
    [µs] and as a multiple of the `waves` kernel."""
    out = []
    for flavour, got in (("python", python), ("compiled", compiled)):
        for n, g in got.items():
            out.append({"flavour": flavour, "components": n, "waves_ns_per_component": 1e9 * g["waves"] / n,
                        "trig_ns_per_component": 1e9 * g["waves_trig"] / n,
                        "phasors_ns_per_component": 1e9 * g["phasors"] / n,
                        **{f"{k}_us": 1e6 * g[k] for k in ("kin_fixed", "kin_moving", "kin_wheeler")},
                        **{f"{k}_x_waves": g[k] / g["waves"] for k in ("kin_fixed", "kin_moving", "kin_wheeler")}})
    return out


def lines(table):
    """Summary lines of ``rows``."""
    out = []
    for flavour, target in (("python", 100.0), ("compiled", 5.0)):
        r = [x for x in table if x["flavour"] == flavour]
        out.append(f"{flavour}: the waves kernel (shared phasors) "
                   + ", ".join(f"{x['components']} components {x['waves_ns_per_component']:.1f} ns" for x in r)
                   + f" per component per step (target ≤ {target:g} ns); with cos/sin every step "
                   + ", ".join(f"{x['trig_ns_per_component']:.1f}" for x in r) + " ns ("
                   + ", ".join(f"{x['trig_ns_per_component'] / x['waves_ns_per_component']:.1f}×" for x in r) + ")")
        out.append(f"{flavour}: kinematics per point per step, × the waves kernel: fixed point "
                   + ", ".join(f"{x['kin_fixed_x_waves']:.2f}×" for x in r) + "; moving point "
                   + ", ".join(f"{x['kin_moving_x_waves']:.2f}×" for x in r) + "; Wheeler "
                   + ", ".join(f"{x['kin_wheeler_x_waves']:.2f}×" for x in r)
                   + f" (at {', '.join(str(x['components']) for x in r)} components)")
    return out


# -- the joined barges in a sea state: the clump's load with and without waves ------------------

JOINED_WAVES = """
[waves]
spectrum = "jonswap"
hs = 3.0
tp = 9.0
direction = 10.0
components = 200
seed = 4
ramp = 20.0
"""


def joined_barges_clump(out, stop=300.0, waves=JOINED_WAVES):
    """models/joined_barges.toml (its clump 8 m under barge A's stern, in a 1 m/s current) run
    by our master in-process, without and with ``waves``: {label: Result}."""
    from ..cosim import inprocess, master
    from ..scene import load_scene
    models = Path(__file__).resolve().parents[3] / "models"
    text = (models / "joined_barges.toml").read_text().replace('"decks/', f'"{(models / "decks").as_posix()}/')
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = {}
    for label, extra in (("current only", ""), ("current and waves", waves)):
        path = out / f"joined_barges_{'waves' if extra else 'calm'}.toml"
        path.write_text(text + extra)
        results[label] = master.run(inprocess.system(load_scene(path)), stop=stop, progress=False)
    return results


def plot_clump(results, path):
    """The clump's load (surge and heave force, on barge A) without and with waves."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for label, r in results.items():
        t = np.asarray(r.time)
        for ax, k, name in zip(axes, (1, 3), ("surge force", "heave force")):
            ax.plot(t, np.asarray(r[f"barge_a.clump.force[{k}]"]) / 1e3, lw=0.8, label=label)
            ax.set_ylabel(f"clump {name} [kN]")
    axes[0].legend(loc="upper right")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title("joined barges: the clump 8 m under barge A's stern (JONSWAP Hs 3 m, Tp 9 s; 1 m/s current)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
