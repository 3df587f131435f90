"""Rigid-body kinematics in the hydrofmu conventions.

Frames: global frame earth-fixed, right-handed, z up, origin on the mean free surface.
Attitude (roll φ, pitch θ, yaw ψ) in rad; body-to-global rotation R = Rz(ψ)·Ry(θ)·Rx(φ).
Velocities and accelerations are 6-vectors [linear of the reference point; angular],
both in global axes.  A 6-vector load is [force; moment about the reference point],
global axes.
"""
import math

import numpy as np


def rotation_rows(attitude):
    """The rows of R = Rz(ψ)·Ry(θ)·Rx(φ) for attitude (φ, θ, ψ) [rad], as three tuples of
    floats (numpy's per-call cost dominates on three angles)."""
    phi, theta, psi = attitude.tolist() if isinstance(attitude, np.ndarray) else map(float, attitude)
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    return ((cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf),
            (sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf),
            (-st, ct * sf, ct * cf))


def rotation(attitude):
    """Body-to-global rotation matrix R = Rz(ψ)·Ry(θ)·Rx(φ) for attitude (φ, θ, ψ) [rad]."""
    return np.array(rotation_rows(attitude))


def cross(a, b):
    """a × b of two 3-vectors, on plain floats (np.cross costs ~15–30 µs a call on
    3-vectors, the hot paths call it every evaluation)."""
    a0, a1, a2 = a.tolist() if isinstance(a, np.ndarray) else a
    b0, b1, b2 = b.tolist() if isinstance(b, np.ndarray) else b
    return np.array(cross_floats(a0, a1, a2, b0, b1, b2))


def rotate(rows, x, y, z):
    """R·(x, y, z) with R given by its rows of floats (``Motion.rot_rows``): three floats.
    The per-step kernels rotate 3-vectors on plain floats (numpy's per-call cost dominates)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rows
    return r00 * x + r01 * y + r02 * z, r10 * x + r11 * y + r12 * z, r20 * x + r21 * y + r22 * z


def rotate_back(rows, x, y, z):
    """Rᵀ·(x, y, z) (global to body axes) with R given by its rows of floats: three floats."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rows
    return r00 * x + r10 * y + r20 * z, r01 * x + r11 * y + r21 * z, r02 * x + r12 * y + r22 * z


def cross_floats(a0, a1, a2, b0, b1, b2):
    """a × b of two 3-vectors given as floats: three floats."""
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def skew(r):
    """Matrix [r]× such that [r]×·a = r × a."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def point_velocity(velocity, r_global):
    """Velocity [m/s] of the point at global offset r from the reference point: v + ω × r."""
    return velocity[:3] + cross(velocity[3:], r_global)


def point_acceleration(velocity, acceleration, r_global):
    """Acceleration of the point at global offset r: a + α × r + ω × (ω × r)."""
    w = velocity[3:]
    return acceleration[:3] + cross(acceleration[3:], r_global) + cross(w, cross(w, r_global))


def transfer(force, r_global, moment=None):
    """6-vector load about the reference point of a force [N] (and moment [N·m]) acting
    at global offset r: [F; r × F + M]."""
    m = cross(r_global, force)
    if moment is not None:
        m = m + moment
    return np.concatenate([force, m])


def point_mass_matrix(mass3, r_global):
    """6×6 mass matrix about the reference point of a point mass at global offset r.

    ``mass3`` is the 3×3 translational mass of the point in global axes (m·I for a
    plain mass, R·diag(AMX, AMY, AMZ)·Rᵀ for directional added mass).  With a = a_ref +
    α × r (linear part), the load on the body is −M6·[a_ref; α] where
    M6 = [[M, −M·[r]×], [[r]×·M, −[r]×·M·[r]×]].
    """
    s = skew(r_global)
    return np.block([[mass3, -mass3 @ s], [s @ mass3, -s @ mass3 @ s]])


def current_velocity(speed, direction_deg):
    """Global current velocity [m/s] for a speed and a 'going to' direction in degrees,
    counter-clockwise from global +x (horizontal, uniform)."""
    return np.array(current_components(speed, direction_deg))


def current_components(speed, direction_deg):
    """``current_velocity`` as a tuple of three floats (for kernels on plain floats)."""
    d = math.radians(direction_deg)
    return (speed * math.cos(d), speed * math.sin(d), 0.0)
