"""Far-field mean drift added to a user's Capytaine dataset (``hydrofmu meandrift``; needs the
`bem-solve` extra: capytaine).

A dataset on disk has no Kochin functions (they need the mesh), so the helper solves the
diffraction (and, for a free body, radiation) problems again on the user's mesh at the
dataset's frequencies and headings with a ``theta`` grid, checks that the result is the
dataset's (the excitation within ``tolerance`` of its peak per dof: the mesh, rotation centre
and environment are the ones the dataset was made with), and adds Capytaine's
``post_pro.far_field_mean_drift_force`` to the dataset as it returns it: ``drift_force_surge``,
``drift_force_sway``, ``drift_force_yaw`` over (omega, wave_direction_k, wave_direction_l),
per unit wave amplitude squared [N/m², N·m/m²] (decks/drift.py reads their diagonal).

Motions: a held body (``fixed``) has none (diffraction only); a free body moves with the
RAO of the dataset's mass (``inertia_matrix``) and hydrostatics (``hydrostatic_stiffness``)
and the re-solved added mass and damping — no mooring, no added damping, which change the
wave-frequency motions little away from the body's own resonances (said in docs/waves.md).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import InputError

TOLERANCE = 0.02   # re-solved excitation against the dataset's, share of each dof's peak


def _need(ds, path, name):
    if name not in ds.coords and name not in ds:
        raise InputError(path, None, name, "missing from the dataset (export it with cpt.export_dataset after "
                                           "fill_dataset(..., hydrostatics=True))")
    return ds[name]


def add_mean_drift(dataset, mesh, out, fixed=False, ntheta=361, lid=True, tolerance=TOLERANCE, log=print,
                   omega_range=None, every=1, directions=None):
    """Write ``out``: the dataset ``dataset`` with the far-field mean drift of the body meshed
    in ``mesh`` (any file cpt.load_mesh reads; the full hull, cut at z = 0 here); ``ntheta``
    Kochin directions over [−Δ, 2π + Δ]; ``lid``: an interior lid against irregular
    frequencies.  The drift may be computed at a subset of the dataset's frequencies
    (``omega_range`` (lo, hi) [rad/s], then every ``every``-th) and headings (``directions``
    [deg], among the dataset's): the other frequencies' rows are NaN (not computed; the reader
    leaves them out and says so).  Returns the drift Dataset."""
    try:
        import capytaine as cpt
        import xarray as xr
        from capytaine.io.xarray import merge_complex_values
    except ImportError:
        raise InputError(dataset, None, "capytaine", "the mean drift needs Capytaine: pip install -e \".[bem-solve]\"")\
            from None
    from .decks.bem import DOF_NAMES
    from .decks.bem_waves import _open
    dataset, mesh, out = Path(dataset), Path(mesh), Path(out)
    ds = merge_complex_values(_open(dataset))
    if "excitation_force" not in ds:
        raise InputError(dataset, None, "excitation_force", "missing: the dataset must hold the diffraction problems "
                                                            "(a wave_direction coordinate) to be checked against")
    dofs = [str(d) for d in np.atleast_1d(ds["influenced_dof"].values)]
    if any("__" in d for d in dofs) or set(dofs) - set(DOF_NAMES):
        raise InputError(dataset, None, "influenced_dof", f"one rigid body's dofs expected ({', '.join(DOF_NAMES)}), "
                                                          f"found {dofs}: the mean drift is computed per single body")
    omega = ds["omega"].values.astype(float)
    finite = omega[np.isfinite(omega) & (omega > 0)]
    if omega_range is not None:
        finite = finite[(finite >= omega_range[0]) & (finite <= omega_range[1])]
    if every != int(every) or every < 1:
        raise InputError("command line", None, "--every", f"a positive integer, found {every}")
    finite = finite[::int(every)]
    if finite.size == 0:
        raise InputError("command line", None, "--omega", f"no frequency of {dataset.name} in {omega_range} rad/s")
    beta = np.atleast_1d(ds["wave_direction"].values.astype(float))
    if directions is not None:
        have = np.degrees(beta)
        pick = []
        for d in directions:
            near = np.flatnonzero(np.abs((have - d + 180.0) % 360.0 - 180.0) < 1e-6)
            if near.size == 0:
                raise InputError("command line", None, "--directions", f"{d:g}° is not a heading of {dataset.name} "
                                                                       f"({', '.join(f'{h:g}' for h in have)})")
            pick.append(beta[near[0]])
        beta = np.array(pick)
    rc = _need(ds, dataset, "rotation_center").values.astype(float).ravel()[:3]
    env = {k: float(np.atleast_1d(_need(ds, dataset, k).values)[0]) for k in ("rho", "g", "water_depth")}
    name = str(np.atleast_1d(ds["body"].values)[0]) if "body" in ds.coords else "body"
    try:
        hull = cpt.load_mesh(str(mesh))
    except Exception as exc:   # capytaine raises several types for unreadable meshes
        raise InputError(mesh, None, "mesh", f"Capytaine cannot read it ({type(exc).__name__}: {exc})") from None
    wet = hull.immersed_part()
    kwargs = {}
    if lid:
        try:
            kwargs["lid_mesh"] = wet.generate_lid(z=-0.01 * float(np.ptp(wet.vertices[:, 2]) or 1.0))
        except Exception as exc:
            raise InputError(mesh, None, "lid", f"cannot make an interior lid ({exc}): pass --no-lid") from None
    body = cpt.FloatingBody(mesh=wet, dofs=cpt.rigid_body_dofs(rotation_center=rc), name=name,
                            center_of_mass=(_need(ds, dataset, "center_of_mass").values.astype(float).ravel()[:3]
                                            if not fixed else rc), **kwargs)
    if not fixed:
        body.inertia_matrix = body.add_dofs_labels_to_matrix(_matrix(ds, dataset, "inertia_matrix", dofs))
        body.hydrostatic_stiffness = body.add_dofs_labels_to_matrix(_matrix(ds, dataset, "hydrostatic_stiffness",
                                                                            dofs))
    delta = 2 * np.pi / max(ntheta - 1, 8)
    coords = {"omega": finite, "wave_direction": beta, "theta": np.linspace(-delta, 2 * np.pi + delta, ntheta),
              "water_depth": [env["water_depth"]], "rho": [env["rho"]], "g": [env["g"]]}
    if not fixed:
        coords["radiating_dof"] = list(body.dofs)
    log(f"solving {finite.size} frequencies × {beta.size} headings on {wet.nb_faces} panels"
        f"{' (held: diffraction only)' if fixed else ''} …")
    new = cpt.BEMSolver().fill_dataset(xr.Dataset(coords=coords), body, hydrostatics=not fixed, progress_bar=False)
    _check(ds, new, dataset, mesh, tolerance)
    if fixed:
        zero = xr.zeros_like(new["kochin_diffraction"].isel(wave_direction=0, drop=True)).expand_dims(
            radiating_dof=["Surge"])
        new["kochin_radiation"] = zero
        x = xr.DataArray(np.zeros((finite.size, 1, beta.size), complex),
                         coords={"omega": finite, "radiating_dof": ["Surge"], "wave_direction": beta},
                         dims=("omega", "radiating_dof", "wave_direction"))
    else:
        x = cpt.post_pro.rao(new)
    drift = cpt.post_pro.far_field_mean_drift_force(x, new)
    merged = ds.copy()
    for var in drift.data_vars:
        merged[var] = drift[var].reindex(omega=omega)      # NaN at ω = 0, ∞: no drift there
    merged.attrs["mean_drift"] = (f"far field (Capytaine post_pro.far_field_mean_drift_force), "
                                  f"{'held body' if fixed else 'free body, RAO of the dataset mass and hydrostatics'}, "
                                  f"{ntheta} Kochin directions, by hydrofmu meandrift")
    out.parent.mkdir(parents=True, exist_ok=True)
    cpt.export_dataset(str(out), merged)
    log(f"wrote {out}: drift_force_surge/sway/yaw at {finite.size} frequencies, {beta.size} headings")
    return drift


def _matrix(ds, path, name, dofs):
    var = _need(ds, path, name)
    var = var.squeeze([d for d in var.dims if d not in ("influenced_dof", "radiating_dof")], drop=True)
    m = var.sel(influenced_dof=dofs, radiating_dof=dofs).values.astype(float)
    if m.shape != (6, 6) or not np.all(np.isfinite(m)):
        raise InputError(path, None, name, "a finite 6 × 6 matrix of the six rigid-body dofs expected")
    return m


def _check(ds, new, dataset, mesh, tolerance):
    """The re-solved excitation is the dataset's, within ``tolerance`` of each dof's peak (a
    dof that is small by symmetry, its noise: of 10 % of the largest peak of its kind)."""
    old = ds["excitation_force"].sel(omega=new["omega"].values, wave_direction=new["wave_direction"].values)
    fresh = new["excitation_force"].transpose(*old.dims)
    dofs = [str(d) for d in old["influenced_dof"].values]
    peaks = {d: float(np.abs(old.sel(influenced_dof=d).values).max()) for d in dofs}
    kind = {d: d in ("Surge", "Sway", "Heave") for d in dofs}
    for dof in dofs:
        a, b = old.sel(influenced_dof=dof).values, fresh.sel(influenced_dof=dof).values
        peak = max(peaks[dof], 0.1 * max(p for d, p in peaks.items() if kind[d] == kind[dof]))
        if peak == 0:
            continue
        diff = np.abs(a - b)
        err = diff.max() / peak
        if err > tolerance:
            at = float(old["omega"].values[np.unravel_index(np.argmax(diff), diff.shape)[
                old.sel(influenced_dof=dof).dims.index("omega")]])
            raise InputError(mesh, None, "mesh", f"the excitation solved on this mesh differs from {dataset.name}'s by "
                                                 f"{100 * err:.2g} % of its {dof} peak at omega = {at:g} rad/s (at most "
                                                 f"{100 * tolerance:g} %): not the mesh, rotation centre or lid the "
                                                 "dataset was made with")
