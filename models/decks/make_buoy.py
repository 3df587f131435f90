"""Make ``buoy.nc``, the BEM result of ``models/buoy_in_waves.toml``: a truncated vertical
cylinder (a discus buoy) solved with Capytaine for radiation, diffraction and Froude–Krylov
forces, with its hydrostatics and rigid-body inertia (deep water, rho = 1025, g = 9.81).

    pip install capytaine && python models/decks/make_buoy.py [OUT.nc]

Buoy: radius 5 m, draft 4 m, rotation centre on the waterline at its axis (the scene's
position), mass = the displaced mass (≈ 321 t), centre of mass 2.5 m below the waterline,
radii of gyration 2.5 m (roll, pitch) and 3.5 m (yaw) about it.  Frequencies 0.05…4 rad/s
every 0.05 and ω = ∞; wave directions 0…330° every 30° (the whole circle: any heading, with
spreading).  Mesh (rotation-symmetric): 64 panels round, 10 down the side, 8 rings across the
bottom, and a lid just below the waterline (irregular frequencies removed): panels ≤ 0.5 m,
an eighth of the wavelength up to about 3.5 rad/s.  ``tests/test_examples.py`` solves one frequency
and heading again and finds the committed file's values.
"""
import sys
from pathlib import Path

import numpy as np

RADIUS, DRAFT, ZG = 5.0, 4.0, -2.5
GYRATION = (2.5, 2.5, 3.5)
RHO, G = 1025.0, 9.81
OMEGA = np.round(np.append(np.arange(1, 81) * 0.05, np.inf), 10)
DIRECTIONS = np.arange(0, 360, 30)


def rigid_inertia(mass: float, cog, centre) -> np.ndarray:
    """6×6 rigid-body inertia about ``centre`` [kg, kg·m, kg·m²] of a body of ``mass`` with its
    centre of mass at ``cog`` and the radii of gyration GYRATION about it (global axes)."""
    r = np.subtract(cog, centre)
    cross = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[:3, 3:] = -mass * cross
    m[3:, :3] = mass * cross
    m[3:, 3:] = mass * np.diag(np.square(GYRATION)) + mass * (r @ r * np.eye(3) - np.outer(r, r))
    return m


def buoy(symmetric: bool = True):
    """The buoy as a Capytaine FloatingBody named ``buoy`` (six rigid dofs about the waterline
    centre); ``symmetric=False``: the same panels as a plain mesh (for the hydrostatics, which
    Capytaine 3.0 does not compute on a rotation-symmetric mesh)."""
    import capytaine as cpt
    # rotation-symmetric meshes: the solver's matrices are block-circulant (a finer mesh for the
    # same time), and the terms the body's symmetry cancels come out zero, not panel noise
    mesh = cpt.mesh_vertical_cylinder(length=2 * DRAFT, radius=RADIUS, center=(0.0, 0.0, 0.0),
                                      resolution=(8, 64, 20), axial_symmetry=True).immersed_part()
    lid = cpt.mesh_disk(radius=RADIUS, center=(0.0, 0.0, -0.01), resolution=(8, 64), axial_symmetry=True)
    if not symmetric:
        mesh, lid = mesh.merged(), lid.merged()
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid,
                            dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                            center_of_mass=(0.0, 0.0, ZG), name="buoy")
    body.mass = body.disp_mass(rho=RHO)
    body.inertia_matrix = body.add_dofs_labels_to_matrix(rigid_inertia(body.mass, (0.0, 0.0, ZG), (0.0, 0.0, 0.0)))
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
    return body


def solve(omega=OMEGA, directions=DIRECTIONS):
    """The dataset of ``buoy()`` at ``omega`` [rad/s] and wave ``directions`` [deg]."""
    import capytaine as cpt
    import xarray as xr
    from capytaine.io.xarray import compute_hydrostatics_dataset
    body = buoy()
    grid = xr.Dataset(coords={"omega": np.asarray(omega, float), "radiating_dof": list(body.dofs),
                              "wave_direction": np.radians(np.asarray(directions, float)),
                              "water_depth": [np.inf], "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(grid, body, hydrostatics=False, progress_bar=False)
    hs = compute_hydrostatics_dataset(buoy(symmetric=False), rho=RHO, g=G)
    hs = hs.assign_coords(radiating_dof=ds.coords["radiating_dof"].to_index(),
                          influenced_dof=ds.coords["influenced_dof"].to_index())
    return xr.merge([ds, hs], compat="no_conflicts", join="outer")


def main(out: Path) -> None:
    import capytaine as cpt
    ds = solve()
    cpt.export_dataset(str(out), ds)
    print(f"wrote {out}: {ds.sizes['omega']} frequencies, {ds.sizes['wave_direction']} directions, "
          f"{out.stat().st_size} bytes, mass {float(ds['inertia_matrix'][0, 0]):.6g} kg")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("buoy.nc"))
