"""Make the wave test datasets: truncated vertical cylinders solved with Capytaine for
radiation, diffraction and Froude–Krylov forces, with hydrostatics and the rigid-body
inertia (deep water, rho = 1025, g = 9.81).

    pip install capytaine && python tests/data/bem/make_waves_data.py [OUTDIR [NAME.nc ...]]

- ``wave_cylinder.nc``: one freely floating cylinder, axis through the origin, wave
  directions 0…90° every 15° (a heading outside them is an error the tests check);
- ``wave_pair.nc``: two such cylinders on the x axis at x = ∓10 m (20 m apart, both away
  from the phase origin), directions 0…330° every 30° (the whole circle, wrapping).

Cylinder: radius 2 m, draft 4 m, rotation centre on the waterline at its axis, mass = the
displaced mass, centre of mass 3 m below the waterline (stable in pitch), radii of gyration
2 m (roll, pitch) and 1.5 m (yaw) about the centre of mass.  Frequencies: 0.05…4 rad/s every 0.05 and ω = ∞.
"""
import sys
from pathlib import Path

import numpy as np

import capytaine as cpt

RADIUS, DRAFT, ZG = 2.0, 4.0, -3.0
GYRATION = (2.0, 2.0, 1.5)
RHO, G = 1025.0, 9.81
# a uniform 0.05 rad/s grid to 4 rad/s (80 frequencies) and ω = ∞: the radiation kernels
# are as long as 2π/Δω resolves (the cross-body ones carry the waves between the bodies)
OMEGA = np.round(np.append(np.arange(1, 81) * 0.05, np.inf), 10)


def rigid_inertia(mass, cog, centre):
    """6×6 rigid-body inertia about ``centre`` [kg, kg·m, kg·m²] of a body of ``mass`` with
    its centre of mass at ``cog`` and the radii of gyration GYRATION about it (global axes)."""
    r = np.subtract(cog, centre)
    cross = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    inertia_g = mass * np.diag(np.square(GYRATION))
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[:3, 3:] = -mass * cross
    m[3:, :3] = mass * cross
    m[3:, 3:] = inertia_g + mass * (r @ r * np.eye(3) - np.outer(r, r))
    return m


def cylinder(name, x):
    mesh = cpt.mesh_vertical_cylinder(length=2 * DRAFT, radius=RADIUS, center=(x, 0.0, 0.0),
                                      resolution=(4, 32, 16)).immersed_part()
    centre = (x, 0.0, 0.0)
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=mesh.generate_lid(z=-0.01),
                            dofs=cpt.rigid_body_dofs(rotation_center=centre),
                            center_of_mass=(x, 0.0, ZG), name=name)
    body.mass = body.disp_mass(rho=RHO)
    body.inertia_matrix = body.add_dofs_labels_to_matrix(rigid_inertia(body.mass, (x, 0.0, ZG), centre))
    body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
    return body


def solve(bodies, directions, omega=OMEGA):
    import xarray as xr
    grid = xr.Dataset(coords={"omega": np.asarray(omega, float), "radiating_dof": list(bodies.dofs),
                              "wave_direction": np.radians(directions), "water_depth": [np.inf],
                              "rho": [RHO], "g": [G]})
    return cpt.BEMSolver().fill_dataset(grid, bodies, hydrostatics=True, progress_bar=False)


def main(out):
    out = Path(out)
    only = set(sys.argv[2:])
    cases = {"wave_cylinder.nc": (cylinder("cyl", 0.0), np.arange(0, 91, 15)),
             "wave_pair.nc": (cylinder("cyl1", -10.0) + cylinder("cyl2", 10.0), np.arange(0, 331, 30))}
    for name, (bodies, directions) in cases.items():
        if only and name not in only:
            continue
        ds = solve(bodies, directions)
        cpt.export_dataset(str(out / name), ds)
        print(f"wrote {out / name}: {ds.sizes['radiating_dof']} dofs, {ds.sizes['omega']} frequencies, "
              f"{len(directions)} directions, {(out / name).stat().st_size} bytes")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent)
