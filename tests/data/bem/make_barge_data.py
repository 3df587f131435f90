"""Make ``barge_finite.nc``: a box barge in finite depth for the Haskind and reciprocity
checks of the BEM readers (tests/test_bem_laws.py).

    pip install capytaine && python tests/data/bem/make_barge_data.py [OUTDIR]

Box 10 m × 5 m × draft 2 m (symmetric about the xz and yz planes, not axisymmetric), rotation
centre on the waterline at its middle, water depth 12 m (kh 0.4 … 4.9 over the frequencies),
ρ = 1025, g = 9.81; 14 frequencies 0.3 … 1.6 rad/s every 0.1 and 2.0 rad/s; wave directions
0 … 315° every 45° (the whole circle: the tests also take the 0/45/90° subset an engineer
often has, completed by the symmetry).  Radiation, diffraction and Froude–Krylov forces, no
hydrostatics (not used).
"""
import sys
from pathlib import Path

import numpy as np

import capytaine as cpt

RHO, G, DEPTH = 1025.0, 9.81, 12.0
OMEGA = np.round(np.append(np.arange(3, 17) * 0.1, 2.0), 10)
DIRECTIONS = np.arange(0, 316, 45)


def main(out):
    import xarray as xr
    mesh = cpt.mesh_parallelepiped(size=(10.0, 5.0, 4.0), center=(0.0, 0.0, 0.0), resolution=(20, 10, 8),
                                   name="barge").immersed_part()
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=mesh.generate_lid(z=-0.01),
                            dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)), name="barge")
    grid = xr.Dataset(coords={"omega": OMEGA, "radiating_dof": list(body.dofs),
                              "wave_direction": np.radians(DIRECTIONS), "water_depth": [DEPTH],
                              "rho": [RHO], "g": [G]})
    ds = cpt.BEMSolver().fill_dataset(grid, body, progress_bar=False)
    path = Path(out) / "barge_finite.nc"
    cpt.export_dataset(str(path), ds)
    print(f"wrote {path}: {ds.sizes['omega']} frequencies, {len(DIRECTIONS)} directions, {path.stat().st_size} bytes")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent)
