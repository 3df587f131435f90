"""Make tests/data/bem/twobody.nc: a surface-piercing float around a coaxial spar (two bodies,
12 dofs, strong interaction), solved with Capytaine for radiation, diffraction and
Froude–Krylov forces, with hydrostatics and the rigid-body inertia (deep water, rho = 1025).

    pip install capytaine && python tests/data/bem/make_twobody.py [OUT.nc]

The shape of a real point-absorber result (a float around a spar, as WEC-Sim's RM3): a fine
grid that stops while the float's radiation damping is still significant, so the transform's
tail beyond the last frequency and its A∞ matter.

- ``float``: a short wide cylinder with a hole (outer radius 10 m, inner 6 m, draft 1.5 m),
  mass = the displaced mass, centre of mass 0.3 m below the waterline, radii of gyration
  6 m (roll, pitch) and 7.5 m (yaw);
- ``spar``: a vertical cylinder of radius 3 m, draft 15 m, in the float's hole, mass = the
  displaced mass, centre of mass 11 m down (ballast: stable in pitch), radii of gyration 4 m
  (roll, pitch) and 2 m (yaw);
- both about the origin (rotation centre on the waterline at the common axis);
- frequencies 0.025…3 rad/s every 0.025 (120) and ω = ∞; one wave direction, 0° (along x).

The water in the 3 m gap between the bodies has a piston (moonpool) resonance near
1.6–1.8 rad/s, sharp in potential flow: the float's heave damping drops to zero at 1.625 rad/s
and A(ω) of several dofs turns negative around it, between grid points the spline of B cannot
follow (a narrower gap, 1.5 m, made it sharper still, at 1.7 and 1.95 rad/s).  Real results of
such bodies have it too.  Coarse on purpose (a small file that solves in a few minutes on one
core); lids against the irregular frequencies on both bodies.
"""
import sys
from pathlib import Path

import numpy as np

import capytaine as cpt

RHO, G = 1025.0, 9.81
R_OUT, R_IN, DRAFT_FLOAT, ZG_FLOAT, GYR_FLOAT = 10.0, 6.0, 1.5, -0.3, (6.0, 6.0, 7.5)
R_SPAR, DRAFT_SPAR, ZG_SPAR, GYR_SPAR = 3.0, 15.0, -11.0, (4.0, 4.0, 2.0)
OMEGA = np.round(np.append(np.arange(1, 121) * 0.025, np.inf), 10)
DIRECTIONS = [0.0]
N_THETA = 32


def rigid_inertia(mass, cog, gyration):
    """6×6 rigid-body inertia about the origin [kg, kg·m, kg·m²] of a body of ``mass`` with its
    centre of mass at ``cog`` and radii of ``gyration`` about it (global axes)."""
    r = np.asarray(cog, float)
    cross = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    m = np.zeros((6, 6))
    m[:3, :3] = mass * np.eye(3)
    m[:3, 3:] = -mass * cross
    m[3:, :3] = mass * cross
    m[3:, 3:] = mass * np.diag(np.square(gyration)) + mass * (r @ r * np.eye(3) - np.outer(r, r))
    return m


def ring_mesh(r_out, r_in, draft, n_z=3, n_r=4, name="float"):
    """Quadrilateral panels of the float's wetted surface: outer wall, inner wall (facing the
    hole) and the flat annular bottom; normals into the fluid."""
    th = np.linspace(0.0, 2 * np.pi, N_THETA + 1)[:-1]
    verts, faces = [], []

    def grid(points):                               # points (rows, N_THETA, 3) → index array
        base = len(verts)
        verts.extend(points.reshape(-1, 3))
        return base + np.arange(points.shape[0] * N_THETA).reshape(points.shape[0], N_THETA)

    def quads(idx, flip):
        for a in range(idx.shape[0] - 1):
            for j in range(N_THETA):
                q = [idx[a, j], idx[a, (j + 1) % N_THETA], idx[a + 1, (j + 1) % N_THETA], idx[a + 1, j]]
                faces.append(q[::-1] if flip else q)

    z = np.linspace(-draft, 0.0, n_z + 1)
    for r, flip in ((r_out, False), (r_in, True)):
        pts = np.stack([np.broadcast_to(r * np.cos(th), (z.size, N_THETA)),
                        np.broadcast_to(r * np.sin(th), (z.size, N_THETA)),
                        np.broadcast_to(z[:, None], (z.size, N_THETA))], axis=-1)
        quads(grid(pts), flip)
    rr = np.linspace(r_in, r_out, n_r + 1)
    pts = np.stack([rr[:, None] * np.cos(th), rr[:, None] * np.sin(th), np.full((rr.size, N_THETA), -draft)], axis=-1)
    quads(grid(pts), False)
    return cpt.Mesh(np.array(verts), np.array(faces), name=name)


def bodies():
    """The float and the spar, each with hydrostatics and inertia about the origin."""
    ring = ring_mesh(R_OUT, R_IN, DRAFT_FLOAT)
    spar = cpt.mesh_vertical_cylinder(length=2 * DRAFT_SPAR, radius=R_SPAR, center=(0.0, 0.0, 0.0),
                                      resolution=(3, 24, 20), name="spar").immersed_part()
    out = []
    for name, mesh, zg, gyr in (("float", ring, ZG_FLOAT, GYR_FLOAT), ("spar", spar, ZG_SPAR, GYR_SPAR)):
        body = cpt.FloatingBody(mesh=mesh, lid_mesh=mesh.generate_lid(z=-0.01),
                                dofs=cpt.rigid_body_dofs(rotation_center=(0.0, 0.0, 0.0)),
                                center_of_mass=(0.0, 0.0, zg), name=name)
        body.mass = body.disp_mass(rho=RHO)
        body.inertia_matrix = body.add_dofs_labels_to_matrix(rigid_inertia(body.mass, (0.0, 0.0, zg), gyr))
        body.hydrostatic_stiffness = body.compute_hydrostatic_stiffness(rho=RHO, g=G)
        out.append(body)
    return out[0] + out[1]


def solve(omega=OMEGA, directions=DIRECTIONS):
    import xarray as xr
    both = bodies()
    grid = xr.Dataset(coords={"omega": np.asarray(omega, float), "radiating_dof": list(both.dofs),
                              "wave_direction": np.radians(directions), "water_depth": [np.inf],
                              "rho": [RHO], "g": [G]})
    return cpt.BEMSolver().fill_dataset(grid, both, hydrostatics=True, progress_bar=False)


def main(out):
    out = Path(out)
    ds = solve()
    cpt.export_dataset(str(out), ds)
    print(f"wrote {out}: {ds.sizes['radiating_dof']} dofs, {ds.sizes['omega']} frequencies, "
          f"{out.stat().st_size} bytes")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).with_name("twobody.nc"))
