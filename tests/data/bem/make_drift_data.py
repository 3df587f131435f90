"""Make the far-field mean drift dataset of the drift tests (tests/test_drift.py):

    pip install -e ".[bem-solve]" && python tests/data/bem/make_drift_data.py [OUTDIR]

A held, deep-draught vertical cylinder (radius 1 m, draught 6 m: k·T = 3…12 at k·a = 0.5…2,
so it is the bottom-mounted cylinder of the closed form to e^{−2kT} ≤ 0.25 %), deep water,
one heading (0°): its mesh written as a WAMIT .gdf and its diffraction dataset as a user has
it (no drift), both in a temporary folder, then the dataset with the far-field mean drift
that ``hydrofmu meandrift --fixed`` adds (``drift_cylinder.nc``, the one file kept).
"""
import sys
from pathlib import Path

import numpy as np

RADIUS, DRAUGHT, RHO, G = 1.0, 6.0, 1025.0, 9.81
KA = np.array([0.5, 0.75, 1.0, 1.5, 2.0])
RESOLUTION = (4, 48, 80)     # (radial, azimuthal, vertical) panels of the whole 2T-long cylinder


def omega(ka=KA):
    return np.sqrt(G * np.asarray(ka, float) / RADIUS)


def write_gdf(mesh, path):
    """A mesh as a WAMIT low-order .gdf (ULEN, g, no symmetry, 4 vertices per panel)."""
    lines = ["cylinder, hydrofmu tests/data/bem/make_drift_data.py", f"1.0 {G}", "0 0", str(mesh.nb_faces)]
    for face in mesh.faces:
        for v in face:
            lines.append(" ".join(repr(float(c)) for c in mesh.vertices[v]))
    Path(path).write_text("\n".join(lines) + "\n")


def user_dataset(ka, gdf, out):
    """The held cylinder's diffraction dataset (no Kochin functions), meshed from ``gdf``."""
    import capytaine as cpt
    import xarray as xr
    wet = cpt.load_mesh(str(gdf)).immersed_part()
    lid = wet.generate_lid(z=-0.01 * float(np.ptp(wet.vertices[:, 2])))
    body = cpt.FloatingBody(mesh=wet, lid_mesh=lid, dofs=cpt.rigid_body_dofs(rotation_center=(0, 0, 0)),
                            center_of_mass=(0, 0, 0), name="cyl")
    grid = xr.Dataset(coords={"omega": omega(ka), "wave_direction": [0.0], "water_depth": [np.inf],
                              "rho": [RHO], "g": [G], "radiating_dof": ["Surge"]})    # (export needs one)
    ds = cpt.BEMSolver().fill_dataset(grid, body, hydrostatics=False, progress_bar=False)
    cpt.export_dataset(str(out), ds)


def make(out, ka=KA, work=None):
    """drift_cylinder.nc in ``out``; the mesh and the user's dataset in ``work`` (a temporary
    folder by default)."""
    import tempfile

    import capytaine as cpt
    from hydrofmu.bem_drift import add_mean_drift
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(work or tmp)
        gdf = work / "drift_cylinder.gdf"
        write_gdf(cpt.mesh_vertical_cylinder(length=2 * DRAUGHT, radius=RADIUS, center=(0, 0, 0),
                                             resolution=RESOLUTION), gdf)
        user_dataset(ka, gdf, work / "drift_cylinder_user.nc")
        add_mean_drift(work / "drift_cylinder_user.nc", gdf, Path(out) / "drift_cylinder.nc", fixed=True)


def main(out):
    make(out)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent)
