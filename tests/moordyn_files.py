"""MoorDyn v2 input files as users write them (front matter, column and unit lines, comments,
options with their descriptions), and the elastic catenary the mooring tests hold MoorDyn
against."""
import math

import numpy as np
from scipy.optimize import fsolve

RHO, G = 1025.0, 9.81
# a studless-chain-like line type: volume-equivalent diameter, mass in air, a soft EA so that
# the stretch (~0.3 %) counts in the shapes
CHAIN = {"diam": 0.1, "mass": 100.0, "ea": 1.0e7}


def wet_weight(diam=CHAIN["diam"], mass=CHAIN["mass"], rho=RHO, g=G):
    """Submerged weight per unit unstretched length [N/m]."""
    return (mass - rho * math.pi * diam ** 2 / 4) * g


def moordyn_file(points, lines, options, bodies=(), chain=CHAIN, title="hydrofmu test mooring"):
    """A MoorDyn v2 file.  ``points``: (attachment, x, y, z) rows, IDs from 1; ``lines``:
    (A, B, length, segments, outputs) rows; ``bodies``: (attachment, x, y, z, r, p, y, mass,
    volume) rows; ``options``: (value, name) rows."""
    out = ["--------------------- MoorDyn Input File ------------------------------------",
           title,
           "---------------------- LINE TYPES ------------------------------------------------------------",
           "TypeName   Diam    Mass/m     EA     BA/-zeta    EI      Cd     Ca     CdAx    CaAx",
           "(name)     (m)     (kg/m)     (N)    (N-s/-)   (N-m^2)   (-)    (-)    (-)     (-)",
           f"chain      {chain['diam']}     {chain['mass']}      {chain['ea']:g}    -1.0        0       "
           "1.2    1.0    0.4     0.5"]
    if bodies:
        out += ["---------------------- BODIES -----------------------------------------------------",
                "ID   Attachment  X0     Y0    Z0     r0      p0     y0     Mass  CG*   I*      Volume   CdA*   Ca*",
                "(#)   (word)     (m)    (m)   (m)   (deg)   (deg)  (deg)   (kg)  (m)  (kg-m^2)  (m^3)   (m^2)  (-)"]
        out += [f"{i}     {b[0]}   {b[1]:g}  {b[2]:g}  {b[3]:g}  {b[4]:g}  {b[5]:g}  {b[6]:g}   {b[7]:g}  0  0  "
                f"{b[8]:g}  0  0" for i, b in enumerate(bodies, 1)]
    out += ["---------------------- POINTS ------------------------------------------------------",
            "ID   Attachment  X       Y     Z      Mass   Volume  CdA    Ca",
            "(#)   (word/ID) (m)     (m)   (m)    (kg)   (m^3)   (m^2)  (-)"]
    out += [f"{i}     {p[0]}     {p[1]:.10g}     {p[2]:.10g}     {p[3]:.10g}     0      0       0      0"
            for i, p in enumerate(points, 1)]
    out += ["---------------------- LINES -------------------------------------------------------",
            "ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs",
            "(#)   (name)     (ID)     (ID)      (m)       (-)      (-)"]
    out += [f"{i}     chain       {ln[0]}        {ln[1]}        {ln[2]:g}        {ln[3]}       {ln[4]}"
            for i, ln in enumerate(lines, 1)]
    out += ["---------------------- OPTIONS -----------------------------------------------------"]
    out += [f"{v:<8} {name:<10} - {name} (set by the test)" for v, name in options]
    out += ["-------------------------------------------------------------------------------------"]
    return "\n".join(out) + "\n"


def catenary(span, height, length, w=None, ea=CHAIN["ea"]):
    """The elastic catenary of a line resting on a frictionless flat bed: (H, V, shape).

    A line of unstretched length L, submerged weight w per unit unstretched length and axial
    stiffness EA runs from an anchor on the bed to a fairlead a horizontal ``span`` X away and
    ``height`` h above it.  On a frictionless bed the horizontal tension H is the same along
    the whole line; the vertical tension grows by w per unit unstretched length from zero at
    the touchdown point, so the fairlead's vertical tension V holds up the suspended length
    L_s = V/w and L_B = L − V/w lies on the bed.  With s the unstretched arc length from the
    touchdown point, a piece ds of the suspended part carries the tension
    T = √(H² + (w·s)²), is stretched to (1 + T/EA)·ds and points along (H, w·s)/T, so

        dx/ds = H/T + H/EA,   dz/ds = w·s/T + w·s/EA,

    which integrate to x(s) = (H/w)·asinh(w·s/H) + H·s/EA and
    z(s) = (H/w)·(√(1 + (w·s/H)²) − 1) + w·s²/(2·EA).  The grounded part, straight under H,
    spans L_B·(1 + H/EA).  The fairlead's position gives the two equations for H and V:

        X = L_B·(1 + H/EA) + x(L_s),   h = z(L_s),

    solved here with scipy.  ``shape(s)`` → (x, z) of the point at unstretched arc length s
    from the anchor (x from the anchor towards the fairlead, z up from the bed)."""
    w = wet_weight() if w is None else w

    def susp(s, h_):
        q = w * s / h_
        return h_ / w * np.arcsinh(q) + h_ * s / ea, h_ / w * (np.sqrt(1 + q * q) - 1) + w * s * s / (2 * ea)

    def equations(u):
        h_, v = u
        x, z = susp(v / w, h_)
        return [(length - v / w) * (1 + h_ / ea) + x - span, z - height]

    guess = [w * span / 4, w * min(length, math.hypot(span, height)) / 2]
    (h_, v), info, ok, msg = fsolve(equations, guess, full_output=True, xtol=1e-13)
    assert ok == 1 and v < w * length, msg   # converged, with some line on the bed
    grounded = length - v / w

    def shape(s):
        s = np.asarray(s, dtype=float)
        x, z = s * (1 + h_ / ea), np.zeros_like(s)
        up = s > grounded
        x_up, z_up = susp(s[up] - grounded, h_)
        x[up], z[up] = grounded * (1 + h_ / ea) + x_up, z_up
        return x, z

    return float(h_), float(v), shape
