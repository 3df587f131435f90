"""Make tests/data/bem/cylinders.nc: two floating vertical cylinders side by side, solved
with Capytaine (radiation only, all 6 rigid dofs of each, deep water, rho = 1025).

    pip install capytaine && python tests/data/bem/make_cylinders.py [OUT.nc]

Coarse on purpose (a small file for the tests): R = 2 m, draft 4 m, centres 8 m apart
along y (4 m gap), 100 frequencies 0.05…5 rad/s plus the infinite-frequency added mass,
a lid against irregular frequencies.  Rotation centres on the waterline at each axis.
"""
import sys
from pathlib import Path

import numpy as np

import capytaine as cpt

RADIUS, DRAFT, GAP_CENTRES = 2.0, 4.0, 8.0
OMEGA = np.append(np.round(np.arange(1, 101) * 0.05, 10), np.inf)
RHO, G = 1025.0, 9.81


def cylinder(name, y):
    mesh = cpt.mesh_vertical_cylinder(length=2 * DRAFT, radius=RADIUS, center=(0.0, y, 0.0),
                                      resolution=(5, 40, 20)).immersed_part()
    return cpt.FloatingBody(mesh=mesh, lid_mesh=mesh.generate_lid(z=-0.01),
                            dofs=cpt.rigid_body_dofs(rotation_center=(0.0, y, 0.0)),
                            center_of_mass=(0.0, y, -DRAFT / 2), name=name)


def solve(omega=OMEGA):
    """The radiation dataset of the two cylinders at the frequencies ``omega`` [rad/s]."""
    import xarray as xr
    bodies = cylinder("cyl1", -GAP_CENTRES / 2) + cylinder("cyl2", GAP_CENTRES / 2)
    grid = xr.Dataset(coords={"omega": np.asarray(omega, float), "radiating_dof": list(bodies.dofs),
                              "water_depth": [np.inf], "rho": [RHO], "g": [G]})
    return cpt.BEMSolver().fill_dataset(grid, bodies, hydrostatics=False)


def main(out):
    ds = solve()
    cpt.export_dataset(str(out), ds)
    print(f"wrote {out}: {ds.sizes['radiating_dof']} dofs, {OMEGA.size} frequencies, {Path(out).stat().st_size} bytes")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).with_name("cylinders.nc"))
