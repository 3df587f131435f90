"""RIFLEX CONB joint kernel: log map, equal-and-opposite loads, freedom codes, the
node's loads, and the co-simulation stability of the default penalty coefficients."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hydrofmu.physics.joint import (BallJoint, default_damping, default_stiffness, effective_mass,
                                    initial_relative_rotation, log_rotation)
from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion

RNG = np.random.default_rng(11)
ATT_A = np.array([0.15, -0.25, 0.8])


def rot_ref(att):
    """R = Rz(ψ)·Ry(θ)·Rx(φ), built by scipy."""
    return Rotation.from_euler("ZYX", att[::-1]).as_matrix()


def att_of(rot):
    """(φ, θ, ψ) of a rotation matrix, by scipy."""
    return Rotation.from_matrix(rot).as_euler("ZYX")[::-1]


def joint(free=(False, False, False), **kw):
    args = dict(name="j", point_a=[5.0, 1.0, -2.0], point_b=[-3.0, 0.5, 1.0],
                k_lin=1e5, c_lin=2e4, k_rot=3e6, c_rot=4e5, free=free)
    args.update(kw)
    return BallJoint(**args)


# -- log map -----------------------------------------------------------------------------

@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-6, 1e-4, 2e-4, 0.3, 1.5, np.pi / 2, 2.0, 3.0,
                                   np.pi - 1e-3, np.pi - 1e-7, np.pi - 1e-10, np.pi - 1e-12])
def test_log_rotation_matches_scipy(angle):
    for _ in range(4):
        axis = RNG.normal(size=3)
        vec = angle * axis / np.linalg.norm(axis)
        # built as R1ᵀ·(R1·R) like the joint's R_Aᵀ·R_B, so rounding is generic
        r1 = Rotation.random(random_state=RNG).as_matrix()
        theta = log_rotation(r1.T @ (r1 @ Rotation.from_rotvec(vec).as_matrix()))
        np.testing.assert_allclose(theta, vec, rtol=0, atol=1e-12)


@pytest.mark.parametrize("angle", [1e-12, 1e-8, 1e-6, 1e-4, 2e-4, 1e-2])
def test_log_rotation_small_angles_relative(angle):
    # a rotation matrix given to rounding: the angle/sin(angle) factor counts
    for _ in range(4):
        axis = RNG.normal(size=3)
        vec = angle * axis / np.linalg.norm(axis)
        np.testing.assert_allclose(log_rotation(Rotation.from_rotvec(vec).as_matrix()), vec, rtol=1e-11)


def test_log_rotation_at_pi():
    for axis in (np.array([1.0, 0, 0]), np.array([0, 0, -1.0]), np.array([1.0, 2.0, -2.0]) / 3.0):
        rot = Rotation.from_rotvec(np.pi * axis).as_matrix()
        theta = log_rotation(rot)
        assert abs(np.linalg.norm(theta) - np.pi) < 1e-12
        np.testing.assert_allclose(Rotation.from_rotvec(theta).as_matrix(), rot, atol=1e-12)


# -- translations, equal and opposite ----------------------------------------------------

def random_motion():
    return Motion(position=RNG.normal(size=3), attitude=0.4 * RNG.normal(size=3),
                  velocity=RNG.normal(size=6), acceleration=RNG.normal(size=6))


def test_force_by_hand_and_equal_opposite():
    j = joint()
    for _ in range(5):
        ma, mb = random_motion(), random_motion()
        la, lb = j.loads(ma, mb, Env())
        ra, rb = rot_ref(ma.attitude) @ j.point_a, rot_ref(mb.attitude) @ j.point_b
        pa, pb = ma.position + ra, mb.position + rb
        va = ma.velocity[:3] + np.cross(ma.velocity[3:], ra)
        vb = mb.velocity[:3] + np.cross(mb.velocity[3:], rb)
        f = 1e5 * (pb - pa) + 2e4 * (vb - va)
        np.testing.assert_allclose(la[:3], f, rtol=1e-12)
        np.testing.assert_allclose(lb[:3], -f, rtol=1e-12)
        # moments about the global origin: the rotational moments cancel, the forces act
        # at p_A and p_B, so the total is (p_A − p_B) × f (zero when the gap closes)
        total = la[3:] + np.cross(ma.position, la[:3]) + lb[3:] + np.cross(mb.position, lb[:3])
        np.testing.assert_allclose(total, np.cross(pa - pb, f), rtol=1e-9, atol=1e-6)
        d, _ = j.deformation(ma, mb)
        np.testing.assert_allclose(d, pb - pa, atol=1e-12)


def test_closed_joint_no_load():
    # B placed so that its joint point coincides with A's, same velocity field, same attitude
    j = joint()
    ma = Motion(position=np.array([1.0, 2.0, 3.0]), attitude=ATT_A, velocity=np.array([0.5, 0, 0, 0, 0, 0]))
    rot = rot_ref(ATT_A)
    pos_b = ma.position + rot @ j.point_a - rot @ j.point_b
    mb = Motion(position=pos_b, attitude=ATT_A, velocity=ma.velocity.copy())
    la, lb = j.loads(ma, mb, Env())
    np.testing.assert_allclose(la, 0.0, atol=1e-8)
    np.testing.assert_allclose(lb, 0.0, atol=1e-8)


# -- rotations and freedom codes ----------------------------------------------------------

def pair(rel_rot, w_rel_a=np.zeros(3)):
    """A at ATT_A; B with R_B = R_A·rel_rot and ω_B − ω_A = R_A·w_rel_a; points coincide."""
    rot_a = rot_ref(ATT_A)
    ma = Motion(attitude=ATT_A, velocity=np.array([0, 0, 0, 0.1, -0.2, 0.05]))
    mb = Motion(attitude=att_of(rot_a @ rel_rot),
                velocity=np.concatenate([np.zeros(3), ma.velocity[3:] + rot_a @ w_rel_a]))
    return ma, mb, rot_a


def rotational_moment(j, ma, mb):
    """Moments of the joint on A and B, minus the moment of the translational force."""
    la, lb = j.loads(ma, mb, Env())
    ra, rb = ma.rot @ j.point_a, mb.rot @ j.point_b
    return la[3:] - np.cross(ra, la[:3]), lb[3:] - np.cross(rb, lb[:3])


def test_free_axis_zero_moment_fixed_axis_resists():
    k, c = 3e6, 4e5
    hinge = joint(free=(False, False, True), point_a=[0, 0, 0], point_b=[0, 0, 0])
    # rotation about A's z (the hinge axis): no moment
    ma, mb, rot_a = pair(Rotation.from_rotvec([0, 0, 0.3]).as_matrix())
    mA, mB = rotational_moment(hinge, ma, mb)
    np.testing.assert_allclose(mA, 0.0, atol=1e-6)
    np.testing.assert_allclose(mB, 0.0, atol=1e-6)
    # bend about A's x: moment k·θ on A about R_A·e_x, opposite on B (restoring)
    ma, mb, rot_a = pair(Rotation.from_rotvec([0.05, 0, 0]).as_matrix())
    mA, mB = rotational_moment(hinge, ma, mb)
    np.testing.assert_allclose(mA, k * 0.05 * rot_a[:, 0], rtol=1e-9)
    np.testing.assert_allclose(mB, -k * 0.05 * rot_a[:, 0], rtol=1e-9)
    # relative spin: damped about y (fixed), not about z (free)
    ma, mb, rot_a = pair(np.eye(3), w_rel_a=np.array([0, 0.2, 0.7]))
    mA, _ = rotational_moment(hinge, ma, mb)
    np.testing.assert_allclose(mA, c * 0.2 * rot_a[:, 1], rtol=1e-9)


def test_ball_hinge_universal_differ_only_in_codes():
    codes = {"rigid": (1, 1, 1), "ball": (0, 0, 0), "hinge": (1, 1, 0), "universal": (1, 0, 0)}
    for _ in range(3):
        ma, mb = random_motion(), random_motion()
        full = joint()
        fa, _ = full.loads(ma, mb, Env())
        m_full = ma.rot.T @ rotational_moment(full, ma, mb)[0]  # A's axes
        for code in codes.values():
            j = joint(free=np.array(code) == 0)
            la, lb = j.loads(ma, mb, Env())
            np.testing.assert_allclose(la[:3], fa[:3], rtol=1e-12)  # same force for every type
            mA, mB = rotational_moment(j, ma, mb)
            np.testing.assert_allclose(ma.rot.T @ mA, np.array(code) * m_full, atol=1e-6)
            np.testing.assert_allclose(mB, -mA, atol=1e-6)


def test_rotational_moment_by_hand():
    j = joint()
    ma, mb = random_motion(), random_motion()
    ra_, rb_ = rot_ref(ma.attitude), rot_ref(mb.attitude)
    theta = Rotation.from_matrix(ra_.T @ rb_).as_rotvec()
    w_rel = ra_.T @ (mb.velocity[3:] - ma.velocity[3:])
    mA, _ = rotational_moment(j, ma, mb)
    np.testing.assert_allclose(mA, ra_ @ (3e6 * theta + 4e5 * w_rel), rtol=1e-9)


def test_initial_relative_rotation():
    att_b = np.array([-0.1, 0.2, -0.5])
    r0 = initial_relative_rotation(ATT_A, att_b)
    j = joint(r_rel0=r0)
    ma, mb = Motion(attitude=ATT_A), Motion(attitude=att_b)
    np.testing.assert_allclose(j.deformation(ma, mb)[1], 0.0, atol=1e-12)
    # B then bent by δ about A's current x axis: θ = (δ, 0, 0) in A's axes
    rot_a = rot_ref(ATT_A)
    mb = Motion(attitude=att_of(rot_a @ Rotation.from_rotvec([0.04, 0, 0]).as_matrix() @ r0))
    np.testing.assert_allclose(j.deformation(ma, mb)[1], [0.04, 0, 0], atol=1e-12)
    # earth: the initial attitude of A is the neutral one
    je = joint(point_b=[0, 0, 0], r_rel0=initial_relative_rotation(ATT_A))
    np.testing.assert_allclose(je.deformation(ma, None)[1], 0.0, atol=1e-12)


def test_earth_side():
    j = joint(point_a=[2.0, 0, 0], point_b=[10.0, 0.0, -1.0])
    ma = Motion(position=np.array([8.5, 0.2, -1.0]), velocity=np.array([0.1, 0, 0, 0, 0, 0.0]))
    la, lb = j.loads(ma, None, Env())
    f = 1e5 * (np.array([10.0, 0, -1.0]) - np.array([10.5, 0.2, -1.0])) + 2e4 * np.array([-0.1, 0, 0])
    np.testing.assert_allclose(la[:3], f, rtol=1e-12)
    np.testing.assert_allclose(la[3:], np.cross([2.0, 0, 0], f), atol=1e-9)
    np.testing.assert_allclose(lb, np.concatenate([-f, np.zeros(3)]), atol=1e-9)  # reaction at the point


# -- the joint node: one lumped body on side A ---------------------------------------------

def test_node_loads_side_a_at_the_joint_point():
    node = LumpedBody("n", offset=[99.0, 99.0, 99.0], am=300.0, ae=0.1, cd=[0, 0, 0], added_mass=[0, 0, 50.0])
    j = joint(node=node)
    bare = joint()
    assert j.uses_acceleration and not j.uses_current and not bare.uses_acceleration
    np.testing.assert_array_equal(j.node.offset, j.point_a)
    env = Env()
    ma, mb = random_motion(), random_motion()
    la, lb = j.loads(ma, mb, env)
    la0, lb0 = bare.loads(ma, mb, env)
    r = rot_ref(ma.attitude) @ j.point_a
    fz = -300.0 * env.g + env.rho * env.g * 0.1
    np.testing.assert_allclose(la - la0, np.concatenate([[0, 0, fz], np.cross(r, [0, 0, fz])]), atol=1e-9)
    np.testing.assert_allclose(lb, lb0)
    # inertia of the node at the joint point, A's motion
    mp = np.diag([300.0, 300.0, 350.0])
    w, acc = ma.velocity[3:], ma.acceleration
    f = -mp @ (acc[:3] + np.cross(acc[3:], r) + np.cross(w, np.cross(w, r)))
    np.testing.assert_allclose(-j.mass_matrix(ma) @ acc + j.velocity_load(ma),
                               np.concatenate([f, np.cross(r, f)]), rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(bare.mass_matrix(ma), np.zeros((6, 6)))


# -- default coefficients and co-simulation stability ----------------------------------------

def test_default_coefficients_numbers():
    mu = 2e6 * 1e6 / 3e6
    wn = 2 * np.pi / (12 * 0.1)  # default: 12 communication steps per joint period
    assert default_stiffness(2e6, 1e6, 0.1) == pytest.approx(mu * wn ** 2)
    assert default_damping(2e6, 1e6, 0.1) == pytest.approx(2 * 0.7 * mu * wn)
    assert default_stiffness(2e6, None, 0.1, n_steps=40) == pytest.approx(2e6 * (2 * np.pi / 4.0) ** 2)
    assert default_damping(2e6, None, 0.1, zeta=0.5) == pytest.approx(2e6 * 2 * np.pi / 1.2)


def test_effective_mass():
    m, ix, iy, iz, L = 1e4, 2e5, 5e5, 8e5, 10.0
    mass6 = np.diag([m, m, m, ix, iy, iz])
    m_lin, i_rot = effective_mass(mass6, [L, 0.0, 0.0])
    # a force along z at (L, 0, 0) also pitches the body: 1/m_eff = 1/m + L²/I_y (least along z)
    assert m_lin == pytest.approx(1.0 / (1.0 / m + L * L / iy))
    assert i_rot == pytest.approx(ix)


def jacobi(j, m_a, m_b, x0, v0, steps, dt, rotational=False):
    """Fixed-step Jacobi co-simulation of two 1-dof sides (B None: the earth). Each side
    integrates its own mass exactly over dt with the joint load held constant.
    Translation along x, or rotation about z (yaw). Returns the history of the gap."""
    x, v = np.array(x0, float), np.array(v0, float)
    k = 5 if rotational else 0
    gaps = []
    for _ in range(steps):
        motions = []
        for i in range(len(x)):
            vel = np.zeros(6)
            vel[k] = v[i]
            if rotational:
                motions.append(Motion(attitude=np.array([0, 0, x[i]]), velocity=vel))
            else:
                motions.append(Motion(position=np.array([x[i], 0, 0]), velocity=vel))
        la, lb = j.loads(motions[0], motions[1] if len(x) > 1 else None, Env())
        f = np.array([la[k], lb[k]])[: len(x)]
        mass = np.array([m_a, m_b])[: len(x)]
        x = x + v * dt + 0.5 * f / mass * dt * dt
        v = v + f / mass * dt
        gaps.append((x[1] if len(x) > 1 else 0.0) - x[0])
    return np.abs(np.array(gaps))


@pytest.mark.parametrize("scale, stable", [(1.0, True), (100.0, False)])
def test_two_masses_jacobi_translation(scale, stable):
    m_a, m_b, dt = 8e6, 3e6, 0.2
    k, c = default_stiffness(m_a, m_b, dt), default_damping(m_a, m_b, dt)
    j = BallJoint("j", [0, 0, 0], [0, 0, 0], k_lin=scale * k, c_lin=c)
    gaps = jacobi(j, m_a, m_b, [0.0, 0.05], [0.3, -0.2], 300, dt)
    if stable:
        assert gaps[-1] < 1e-8 * 0.05 and gaps.max() < 0.1
    else:
        assert not np.isfinite(gaps[-1]) or gaps[-1] > 1e3 * 0.05  # diverged (may overflow)


@pytest.mark.parametrize("scale, stable", [(1.0, True), (100.0, False)])
def test_two_masses_jacobi_rotation(scale, stable):
    i_a, i_b, dt = 4e9, 1e9, 0.1
    k, c = default_stiffness(i_a, i_b, dt), default_damping(i_a, i_b, dt)
    j = BallJoint("j", [0, 0, 0], [0, 0, 0], k_lin=0.0, c_lin=0.0, k_rot=scale * k, c_rot=c,
                  free=[False, False, False])
    gaps = jacobi(j, i_a, i_b, [0.0, 0.02], [0.0, 0.01], 300, dt, rotational=True)
    if stable:
        assert gaps[-1] < 1e-8 * 0.02
    else:
        assert gaps.max() > 1.0  # diverged (the angle wraps at ±π, so look at the peak)


def test_jacobi_earth_default_stable():
    m_a, dt = 5e6, 0.05
    j = BallJoint("j", [0, 0, 0], [0, 0, 0], k_lin=default_stiffness(m_a, None, dt),
                  c_lin=default_damping(m_a, None, dt))
    gaps = jacobi(j, m_a, None, [0.1], [0.0], 300, dt)
    assert gaps[-1] < 1e-8 * 0.1


@pytest.mark.parametrize("zeta", [0.2, 0.5, 0.7, 0.9])
def test_stability_limit_of_the_docstring(zeta):
    """One Jacobi step against the earth is linear in (x, v): its spectral radius crosses 1
    at Ω = ω_n·dt = min(4ζ, 1/ζ), the limit derived in default_stiffness."""
    m, dt = 1e6, 0.1
    limit = min(4 * zeta, 1 / zeta)
    for factor, stable in ((0.97, True), (1.03, False)):
        wn = factor * limit / dt
        j = BallJoint("j", [0, 0, 0], [0, 0, 0], k_lin=m * wn * wn, c_lin=2 * zeta * m * wn)
        cols = []
        for x0, v0 in ((1.0, 0.0), (0.0, 1.0)):
            la, _ = j.loads(Motion(position=np.array([x0, 0, 0]), velocity=np.array([v0, 0, 0, 0, 0, 0])), None, Env())
            f = la[0]
            cols.append([x0 + v0 * dt + 0.5 * f / m * dt * dt, v0 + f / m * dt])
        radius = max(abs(np.linalg.eigvals(np.array(cols).T)))
        assert (radius < 1.0) == stable, (zeta, factor, radius)
