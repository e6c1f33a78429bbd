#!/usr/bin/env python3
"""Basilisk peer for the environmental torques: at fixed, documented states, the torque in
body axes from Basilisk's own modules, for polhode's four environmental effectors.

  gravity_gradient  GravityGradientEffector (Earth gravity body, mu set to polhode's)
  magnetic_dipole   MagneticFieldCenteredDipole (B) + MtbEffector (three rods along the body
                    axes commanded to the dipole's components: tau = m x B)
  aerodynamic       ExponentialAtmosphere (one band of Vallado's table) + ZeroWindModel
                    (co-rotating air) + FacetDragDynamicEffector (one facet facing the wind)
  solar_pressure    FacetSRPDynamicEffector (one facet) + Eclipse (shadow factor)

Each state is one fresh Basilisk simulation: a spacecraft hub at the state's position,
velocity and attitude, the environment modules run once at t = 0 (so that their messages
are written), then the effector's computeForceTorque is called and its
torqueExternalPntB_B read.

Where Basilisk's model differs from polhode's, Basilisk is given polhode's inputs so that
the comparison isolates the torque computation (each is recorded in the JSON and in the
notes of docs/peers.md):
- the orbit state: position and velocity from the elements with Basilisk's orbitalMotion
  (f -> E -> M, M + n t, M -> E -> f, elem2rv), mu = 3.986004418e14 m^3/s^2 (polhode's,
  WGS-84) instead of Basilisk's createEarth() 3.98600436e14;
- the dipole: the IGRF-14 first-degree coefficients at the decimal year of the instant
  (typed below from the IGRF-14 coefficient file, linear between the 5-yearly snapshots,
  secular variation after 2025), reference radius 6371.2 km, and the Earth rotation angle
  (IERS Conventions 2010, eq. 5.15, UT1 = UTC) as the planet's J20002Pfix;
- the atmosphere: the band of Vallado's Table 8-4 (4th ed., 2013) holding the altitude,
  given to ExponentialAtmosphere as baseDensity = rho0, scaleHeight = H and
  planetRadius = R_E + h0, so that its rho0 exp(-(r - planetRadius)/H) is the band's
  formula; the wind model's planet rate is (0, 0, 7.292115e-5) rad/s; the facet's normal is
  the relative wind in body axes (polhode's area does not depend on attitude);
- the Sun: the low-precision solar coordinates (Astronomical Almanac, Vallado Algorithm 29)
  at the instant, placed at r_sc + d s_hat so that Basilisk's spacecraft-to-Sun vector is
  polhode's geocentric direction and distance; Basilisk's facetSRPDynamicEffector uses a
  solar flux of 1368 W/m^2, polhode 1361 W/m^2 (Kopp & Lean 2011), so the facet's area is
  A * 1361/1368. The shadow comes from Basilisk's Eclipse module (conical umbra and
  penumbra) fed the same Sun: the states are chosen well inside the umbra or well in the
  light, where it agrees with polhode's cylinder.

Writes results/basilisk_environment.json. tests/basilisk_environment.rs evaluates polhode's
effectors at the same states and compares.
"""
import json
import math
import os
import time
from datetime import datetime, timezone

import numpy as np
from Basilisk.architecture import messaging
from Basilisk.simulation import (GravityGradientEffector, MtbEffector, eclipse, exponentialAtmosphere,
                                 facetDragDynamicEffector, facetSRPDynamicEffector,
                                 magneticFieldCenteredDipole, spacecraft, zeroWindModel)
from Basilisk.utilities import SimulationBaseClass, macros, orbitalMotion as om, simIncludeGravBody
from Basilisk.utilities import RigidBodyKinematics as rbk

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results")

# polhode's constants (src/orbit/body.rs, src/orbit/magnetic.rs, src/effectors/solar_pressure.rs).
MU = 3.986004418e14            # m^3/s^2, WGS-84
R_EARTH = 6378137.0            # m, WGS-84 equatorial radius
OMEGA_EARTH = 7.292115e-5      # rad/s, WGS-84
IGRF_RADIUS = 6371200.0        # m, IGRF reference radius
SOLAR_IRRADIANCE = 1361.0      # W/m^2 (Kopp & Lean 2011)
BASILISK_SOLAR_FLUX = 1368.0   # W/m^2, facetSRPDynamicEffector.cpp's solarRadFlux
AU = 149597870700.0            # m, IAU 2012 B2
J2000_UNIX = 946728000.0       # s, 2000-01-01T12:00:00 UTC
TT_MINUS_UTC = 69.184          # s, 32.184 + 37

# IGRF-14 first-degree Gauss coefficients (nT), 1965.0 to 2025.0 every 5 years (DGRF to 2020,
# IGRF 2025), and the predicted secular variation 2025-2030 (nT/yr): IAGA Working Group V-MOD,
# igrf14coeffs.txt (NOAA NCEI).
IGRF14 = {
    "g10": [-30334.0, -30220.0, -30100.0, -29992.0, -29873.0, -29775.0, -29692.0, -29619.4,
            -29554.63, -29496.57, -29441.46, -29403.41, -29350.0],
    "g11": [-2119.0, -2068.0, -2013.0, -1956.0, -1905.0, -1848.0, -1784.0, -1728.2, -1669.05,
            -1586.42, -1501.77, -1451.37, -1410.3],
    "h11": [5776.0, 5737.0, 5675.0, 5604.0, 5500.0, 5406.0, 5306.0, 5186.1, 5077.99, 4944.26,
            4795.99, 4653.35, 4545.5],
}
IGRF14_SV = {"g10": 12.6, "g11": 10.0, "h11": -21.5}

# Vallado (2013), Table 8-4: base altitude (km), density (kg/m^3), scale height (km).
VALLADO_8_4 = [
    (0, 1.225, 7.249), (25, 3.899e-2, 6.349), (30, 1.774e-2, 6.682), (40, 3.972e-3, 7.554),
    (50, 1.057e-3, 8.382), (60, 3.206e-4, 7.714), (70, 8.770e-5, 6.549), (80, 1.905e-5, 5.799),
    (90, 3.396e-6, 5.382), (100, 5.297e-7, 5.877), (110, 9.661e-8, 7.263), (120, 2.438e-8, 9.473),
    (130, 8.484e-9, 12.636), (140, 3.845e-9, 16.149), (150, 2.070e-9, 22.523),
    (180, 5.464e-10, 29.740), (200, 2.789e-10, 37.105), (250, 7.248e-11, 45.546),
    (300, 2.418e-11, 53.628), (350, 9.518e-12, 53.298), (400, 3.725e-12, 58.515),
    (450, 1.585e-12, 60.828), (500, 6.967e-13, 63.822), (600, 1.454e-13, 71.835),
    (700, 3.614e-14, 88.667), (800, 1.170e-14, 124.64), (900, 5.245e-15, 181.05),
    (1000, 3.019e-15, 268.00),
]

DEG = math.pi / 180.0


def log(msg):
    print(f"[basilisk-env {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def unix_ns(iso):
    """Unix ns of an ISO-8601 UTC instant with whole seconds."""
    d = datetime.strptime(iso, "%Y-%m-%dT%H:%M:%SZ").replace(tzinfo=timezone.utc)
    return int(d.timestamp()) * 1_000_000_000


# ---------------------------------------------------------------------------------------------
# polhode's inputs, written out here from their definitions
# ---------------------------------------------------------------------------------------------

def decimal_year(unix_s):
    """Year plus the elapsed fraction of it (365 or 366 days), UTC."""
    d = datetime.fromtimestamp(unix_s, tz=timezone.utc)
    start = datetime(d.year, 1, 1, tzinfo=timezone.utc).timestamp()
    end = datetime(d.year + 1, 1, 1, tzinfo=timezone.utc).timestamp()
    return d.year + (unix_s - start) / (end - start)


def igrf14_dipole(year):
    """(g10, g11, h11) in nT: linear between snapshots, secular variation after 2025.0."""
    last = len(IGRF14["g10"]) - 1
    x = (year - 1965.0) / 5.0
    if x >= last:
        dt = year - 2025.0
        return tuple(IGRF14[k][last] + IGRF14_SV[k] * dt for k in ("g10", "g11", "h11"))
    k = min(max(int(math.floor(x)), 0), last - 1)
    f = x - k
    return tuple(IGRF14[c][k] + f * (IGRF14[c][k + 1] - IGRF14[c][k]) for c in ("g10", "g11", "h11"))


def earth_rotation_angle(epoch_unix_s, t):
    """ERA (rad): 2 pi (0.7790572732640 + 1.00273781191135448 D_U), D_U = JD(UT1) - 2451545,
    at t s after the whole-second epoch; the whole days of D_U (whole turns in its 1.0 D_U
    part) are split off in integers first, which keeps the day fraction's resolution."""
    whole, rem = divmod(int(epoch_unix_s) - int(J2000_UNIX), 86400)
    frac = (rem + t) / 86400.0
    turns = 0.7790572732640 + frac + 0.00273781191135448 * (whole + frac)
    return 2.0 * math.pi * (turns % 1.0)


def sun_low_precision(unix_s):
    """Unit vector to the Sun (mean equator and equinox of date) and distance (AU):
    the Astronomical Almanac's low-precision formulas (Vallado Algorithm 29)."""
    t_ut1 = (unix_s - J2000_UNIX) / (86400.0 * 36525.0)
    t_tdb = (unix_s + TT_MINUS_UTC - J2000_UNIX) / (86400.0 * 36525.0)
    lam_m = (280.460 + 36000.771 * t_ut1) % 360.0
    m = math.radians((357.5291092 + 35999.05034 * t_tdb) % 360.0)
    lam = math.radians(lam_m + 1.914666471 * math.sin(m) + 0.019994643 * math.sin(2 * m))
    d = 1.000140612 - 0.016708617 * math.cos(m) - 0.000139589 * math.cos(2 * m)
    eps = math.radians(23.439291 - 0.0130042 * t_tdb)
    return np.array([math.cos(lam), math.cos(eps) * math.sin(lam), math.sin(eps) * math.sin(lam)]), d


def in_cylinder_shadow(r, s_hat):
    along = r @ s_hat
    return along < 0.0 and np.linalg.norm(r - along * s_hat) < R_EARTH


def atmosphere_band(h):
    """The row of Vallado's Table 8-4 holding the altitude h (m), chosen, as polhode does, at
    the altitude rounded to the mm (a circular orbit at a band base stays in that band)."""
    km = round(h * 1e3) / 1e6
    return [row for row in VALLADO_8_4 if row[0] <= km][-1]


# ---------------------------------------------------------------------------------------------
# Orbit state and attitude, with Basilisk's own utilities
# ---------------------------------------------------------------------------------------------

def orbit_state(el, t):
    """ECI position (m) and velocity (m/s) at t s after the epoch, two-body, with
    Basilisk's orbitalMotion (angles in the JSON in degrees)."""
    a, e = el["a"], el["e"]
    f0 = el["nu"] * DEG
    m0 = om.E2M(om.f2E(f0, e), e)
    n = math.sqrt(MU / a ** 3)
    f = om.E2f(om.M2E(m0 + n * t, e), e)
    oe = om.ClassicElements()
    oe.a, oe.e, oe.i = a, e, el["i"] * DEG
    oe.Omega, oe.omega, oe.f = el["raan"] * DEG, el["argp"] * DEG, f
    r, v = om.elem2rv(MU, oe)
    return np.array(r, dtype=float), np.array(v, dtype=float)


def mrp(q):
    """sigma_BN of the quaternion q = (w, x, y, z) that maps body to inertial components."""
    q = np.array(q, dtype=float)
    q = q / np.linalg.norm(q)
    if q[0] < 0:
        q = -q
    return q[1:] / (1.0 + q[0])


def dcm_bn(q):
    return np.array(rbk.MRP2C(mrp(q)))


# ---------------------------------------------------------------------------------------------
# One Basilisk simulation per state
# ---------------------------------------------------------------------------------------------

class Sim:
    """A spacecraft hub at (r, v, attitude) in a one-task simulation."""

    def __init__(self, r, v, q, inertia=None):
        self.sim = SimulationBaseClass.SimBaseClass()
        proc = self.sim.CreateNewProcess("proc")
        proc.addTask(self.sim.CreateNewTask("task", macros.sec2nano(1.0)))
        sc = spacecraft.Spacecraft()
        sc.ModelTag = "sc"
        sc.hub.mHub = 100.0
        sc.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
        sc.hub.IHubPntBc_B = (np.diag([1.0, 2.0, 3.0]) if inertia is None else np.array(inertia)).tolist()
        sc.hub.r_CN_NInit = [[x] for x in r]
        sc.hub.v_CN_NInit = [[x] for x in v]
        sc.hub.sigma_BNInit = [[x] for x in mrp(q)]
        sc.hub.omega_BN_BInit = [[0.0], [0.0], [0.0]]
        self.sc = sc
        self.keep = []
        self.sim.AddModelToTask("task", sc, 100)

    def add(self, module, priority):
        self.keep.append(module)
        self.sim.AddModelToTask("task", module, priority)

    def message(self, msg_class, payload):
        m = msg_class().write(payload)
        self.keep.append((m, payload))
        return m

    def run(self):
        self.sim.InitializeSimulation()
        self.sim.ConfigureStopTime(0)
        self.sim.ExecuteSimulation()


def planet_payload(name, position, j2000_to_fixed=None):
    p = messaging.SpicePlanetStateMsgPayload()
    p.PlanetName = name
    p.PositionVector = list(position)
    p.VelocityVector = [0.0, 0.0, 0.0]
    p.J20002Pfix = (np.eye(3) if j2000_to_fixed is None else j2000_to_fixed).tolist()
    return p


def vec(x):
    return [float(v) for v in np.array(x, dtype=float).ravel()]


def gravity_gradient(case):
    r, v = orbit_state(case["elements"], case["t"])
    s = Sim(r, v, case["attitude"], case["inertia"])
    grav = simIncludeGravBody.gravBodyFactory()
    earth = grav.createEarth()
    earth.isCentralBody = True
    earth.mu = MU
    s.sc.gravField.gravBodies = spacecraft.GravBodyVector(list(grav.gravBodies.values()))
    gg = GravityGradientEffector.GravityGradientEffector()
    gg.ModelTag = "gg"
    gg.addPlanetName(earth.planetName)
    s.sc.addDynamicEffector(gg)
    s.add(gg, 10)
    s.keep.append(grav)
    s.run()
    gg.computeForceTorque(0.0, 0.0)
    return {"r_eci": vec(r), "v_eci": vec(v), "sigma_bn": vec(mrp(case["attitude"])),
            "mu": MU, "torque": vec(gg.torqueExternalPntB_B)}


def magnetic_dipole(case):
    t = case["t"]
    unix_s = unix_ns(case["epoch"]) * 1e-9 + t
    r, v = orbit_state(case["elements"], t)
    s = Sim(r, v, case["attitude"])
    year = decimal_year(unix_s)
    g10, g11, h11 = igrf14_dipole(year)
    theta = earth_rotation_angle(unix_ns(case["epoch"]) // 1_000_000_000, t)
    c, sn = math.cos(theta), math.sin(theta)
    j2000_to_ecef = np.array([[c, sn, 0.0], [-sn, c, 0.0], [0.0, 0.0, 1.0]])  # R3(theta)
    mag = magneticFieldCenteredDipole.MagneticFieldCenteredDipole()
    mag.ModelTag = "dipole"
    mag.g10, mag.g11, mag.h11 = g10 * 1e-9, g11 * 1e-9, h11 * 1e-9
    mag.planetRadius = IGRF_RADIUS
    mag.planetPosInMsg.subscribeTo(s.message(messaging.SpicePlanetStateMsg,
                                             planet_payload("earth", [0.0, 0.0, 0.0], j2000_to_ecef)))
    mag.addSpacecraftToModel(s.sc.scStateOutMsg)
    s.add(mag, 50)
    cmd = messaging.MTBCmdMsgPayload()
    cmd.mtbDipoleCmds = list(case["moment"])
    params = messaging.MTBArrayConfigMsgPayload()
    params.numMTB = 3
    params.GtMatrix_B = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]   # rods along x, y, z
    params.maxMtbDipoles = [1e6, 1e6, 1e6]
    mtb = MtbEffector.MtbEffector()
    mtb.ModelTag = "mtb"
    mtb.mtbCmdInMsg.subscribeTo(s.message(messaging.MTBCmdMsg, cmd))
    mtb.mtbParamsInMsg.subscribeTo(s.message(messaging.MTBArrayConfigMsg, params))
    mtb.magInMsg.subscribeTo(mag.envOutMsgs[0])
    s.sc.addDynamicEffector(mtb)
    s.add(mtb, 10)
    s.run()
    mtb.computeForceTorque(0.0, 0.0)
    b_n = np.array(mag.envOutMsgs[0].read().magField_N)
    return {"r_eci": vec(r), "v_eci": vec(v), "sigma_bn": vec(mrp(case["attitude"])),
            "decimal_year": year, "g10_nT": g10, "g11_nT": g11, "h11_nT": h11,
            "earth_rotation_angle": theta, "b_eci": vec(b_n),
            "b_body": vec(dcm_bn(case["attitude"]) @ b_n), "torque": vec(mtb.torqueExternalPntB_B)}


def aerodynamic(case):
    r, v = orbit_state(case["elements"], case["t"])
    s = Sim(r, v, case["attitude"])
    h0, rho0, scale = atmosphere_band(np.linalg.norm(r) - R_EARTH)
    zero_planet = s.message(messaging.SpicePlanetStateMsg, planet_payload("earth", [0.0, 0.0, 0.0]))
    atmo = exponentialAtmosphere.ExponentialAtmosphere()
    atmo.ModelTag = "atmosphere"
    atmo.planetRadius = R_EARTH + h0 * 1e3
    atmo.baseDensity = rho0
    atmo.scaleHeight = scale * 1e3
    atmo.planetPosInMsg.subscribeTo(zero_planet)
    atmo.addSpacecraftToModel(s.sc.scStateOutMsg)
    s.add(atmo, 50)
    wind = zeroWindModel.ZeroWindModel()
    wind.ModelTag = "wind"
    wind.setPlanetOmega_N([0.0, 0.0, OMEGA_EARTH])
    wind.planetPosInMsg.subscribeTo(zero_planet)
    wind.addSpacecraftToModel(s.sc.scStateOutMsg)
    s.add(wind, 50)
    v_rel_b = dcm_bn(case["attitude"]) @ (v - np.cross([0.0, 0.0, OMEGA_EARTH], r))
    normal = v_rel_b / np.linalg.norm(v_rel_b)
    drag = facetDragDynamicEffector.FacetDragDynamicEffector()
    drag.ModelTag = "drag"
    drag.addFacet(case["area"], case["drag_coefficient"], normal.tolist(), list(case["center_of_pressure"]))
    drag.atmoDensInMsg.subscribeTo(atmo.envOutMsgs[0])
    drag.windVelInMsg.subscribeTo(wind.envOutMsgs[0])
    s.sc.addDynamicEffector(drag)
    s.add(drag, 10)
    s.run()
    drag.computeForceTorque(0.0, 0.0)
    rho = atmo.envOutMsgs[0].read().neutralDensity
    v_air = np.array(wind.envOutMsgs[0].read().v_air_N)
    return {"r_eci": vec(r), "v_eci": vec(v), "sigma_bn": vec(mrp(case["attitude"])),
            "altitude": float(np.linalg.norm(r) - R_EARTH), "band": [h0, rho0, scale],
            "density": rho, "air_velocity_eci": vec(v_air), "wind_body": vec(drag.v_B),
            "facet_normal": vec(normal), "torque": vec(drag.torqueExternalPntB_B)}


def solar_pressure(case):
    t = case["t"]
    unix_s = unix_ns(case["epoch"]) * 1e-9 + t
    r, v = orbit_state(case["elements"], t)
    s = Sim(r, v, case["attitude"])
    s_hat, d_au = sun_low_precision(unix_s)
    sun_pos = r + d_au * AU * s_hat
    sun = s.message(messaging.SpicePlanetStateMsg, planet_payload("sun", sun_pos))
    earth = s.message(messaging.SpicePlanetStateMsg, planet_payload("earth", [0.0, 0.0, 0.0]))
    ecl = eclipse.Eclipse()
    ecl.ModelTag = "eclipse"
    ecl.sunInMsg.subscribeTo(sun)
    ecl.addPlanetToModel(earth)
    ecl.rEqCustom = R_EARTH
    ecl.addSpacecraftToModel(s.sc.scStateOutMsg)
    s.add(ecl, 50)
    srp = facetSRPDynamicEffector.FacetSRPDynamicEffector()
    srp.ModelTag = "srp"
    srp.setNumFacets(1)
    srp.setNumArticulatedFacets(0)
    area = case["area"] * SOLAR_IRRADIANCE / BASILISK_SOLAR_FLUX
    srp.addFacet(area, np.eye(3).tolist(), list(case["normal"]), [1.0, 0.0, 0.0],
                 list(case["center_of_pressure"]), case["diffuse"], case["specular"])
    srp.sunInMsg.subscribeTo(sun)
    srp.sunEclipseInMsg.subscribeTo(ecl.eclipseOutMsgs[0])
    s.sc.addDynamicEffector(srp)
    s.add(srp, 10)
    s.run()
    srp.computeForceTorque(0.0, 0.0)
    shadow = ecl.eclipseOutMsgs[0].read().shadowFactor
    return {"r_eci": vec(r), "v_eci": vec(v), "sigma_bn": vec(mrp(case["attitude"])),
            "sun_eci": vec(s_hat), "sun_distance_au": d_au, "sun_position_fed": vec(sun_pos),
            "basilisk_area": area, "shadow_factor": shadow,
            "cylinder_shadow": bool(in_cylinder_shadow(r, s_hat)),
            "sun_body": vec(dcm_bn(case["attitude"]) @ s_hat), "torque": vec(srp.torqueExternalPntB_B)}


# ---------------------------------------------------------------------------------------------
# The states
# ---------------------------------------------------------------------------------------------

def quat(axis, angle_deg):
    axis = np.array(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    h = 0.5 * angle_deg * DEG
    return [math.cos(h), *(math.sin(h) * axis)]


EXPLORER1 = {"a": R_EARTH + 0.5 * (358e3 + 2550e3), "e": (2550e3 - 358e3) / (2 * R_EARTH + 358e3 + 2550e3),
             "i": 33.24, "raan": 0.0, "argp": 0.0, "nu": 0.0}
INERTIA_FULL = [[12.0, -0.8, 0.5], [-0.8, 17.0, 1.1], [0.5, 1.1, 9.0]]
INERTIA_DIAG = [[4.0, 0.0, 0.0], [0.0, 6.0, 0.0], [0.0, 0.0, 7.5]]


def cases():
    gg = [
        {"label": "ISS-like circular 400 km, identity attitude",
         "elements": {"a": R_EARTH + 400e3, "e": 0.0, "i": 51.6, "raan": 30.0, "argp": 0.0, "nu": 45.0},
         "t": 0.0, "attitude": [1, 0, 0, 0], "inertia": INERTIA_FULL},
        {"label": "circular 700 km sun-synchronous, tilted 40 deg about (1,2,3), t = 1500 s",
         "elements": {"a": R_EARTH + 700e3, "e": 0.0, "i": 98.2, "raan": 120.0, "argp": 0.0, "nu": 10.0},
         "t": 1500.0, "attitude": quat([1, 2, 3], 40.0), "inertia": INERTIA_FULL},
        {"label": "Explorer 1 orbit at perigee, principal inertia, tilted 25 deg about y",
         "elements": EXPLORER1, "t": 0.0, "attitude": quat([0, 1, 0], 25.0), "inertia": INERTIA_DIAG},
        {"label": "Explorer 1 orbit, t = 2000 s (near apogee), tumbled 130 deg about (-1,1,0.5)",
         "elements": EXPLORER1, "t": 2000.0, "attitude": quat([-1, 1, 0.5], 130.0), "inertia": INERTIA_FULL},
        {"label": "Molniya-like e = 0.72, t = 9000 s, tilted 75 deg about (0.3,-0.2,1)",
         "elements": {"a": 26560e3, "e": 0.72, "i": 63.4, "raan": 250.0, "argp": 270.0, "nu": 20.0},
         "t": 9000.0, "attitude": quat([0.3, -0.2, 1], 75.0), "inertia": INERTIA_FULL},
        {"label": "GEO, tilted 170 deg about (2,-1,1)",
         "elements": {"a": 42164e3, "e": 0.0002, "i": 0.05, "raan": 80.0, "argp": 10.0, "nu": 200.0},
         "t": 600.0, "attitude": quat([2, -1, 1], 170.0), "inertia": INERTIA_FULL},
    ]
    md = [
        {"label": "CubeSat 500 km polar, 2020-01-01, identity attitude",
         "epoch": "2020-01-01T00:00:00Z", "t": 0.0,
         "elements": {"a": R_EARTH + 500e3, "e": 0.0, "i": 97.4, "raan": 40.0, "argp": 0.0, "nu": 0.0},
         "attitude": [1, 0, 0, 0], "moment": [0.1, -0.05, 0.2]},
        {"label": "CubeSat 500 km polar, 2022-06-15 + 2400 s, tilted 60 deg about (1,1,0)",
         "epoch": "2022-06-15T08:30:00Z", "t": 2400.0,
         "elements": {"a": R_EARTH + 500e3, "e": 0.0, "i": 97.4, "raan": 40.0, "argp": 0.0, "nu": 0.0},
         "attitude": quat([1, 1, 0], 60.0), "moment": [0.1, -0.05, 0.2]},
        {"label": "ISS-like 51.6 deg, 2026-03-01 (secular variation), tumbled 150 deg",
         "epoch": "2026-03-01T18:00:00Z", "t": 1000.0,
         "elements": {"a": R_EARTH + 420e3, "e": 0.0007, "i": 51.6, "raan": 300.0, "argp": 80.0, "nu": 100.0},
         "attitude": quat([-0.5, 0.2, 1.0], 150.0), "moment": [-1.0, 0.4, 0.3]},
        {"label": "Explorer 1 orbit, 1975-07-04 + 3000 s (DGRF), tilted 35 deg about z",
         "epoch": "1975-07-04T12:00:00Z", "t": 3000.0, "elements": EXPLORER1,
         "attitude": quat([0, 0, 1], 35.0), "moment": [0.0, 0.0, 1.5]},
        {"label": "equatorial 800 km, 2010-09-23 (an interpolated year), tilted 90 deg about x",
         "epoch": "2010-09-23T03:15:00Z", "t": 500.0,
         "elements": {"a": R_EARTH + 800e3, "e": 0.001, "i": 0.0, "raan": 0.0, "argp": 0.0, "nu": 270.0},
         "attitude": quat([1, 0, 0], 90.0), "moment": [0.3, 0.3, -0.3]},
        {"label": "GEO, 2029-12-31, tilted 20 deg about (1,-3,2)",
         "epoch": "2029-12-31T00:00:00Z", "t": 0.0,
         "elements": {"a": 42164e3, "e": 0.0, "i": 0.1, "raan": 0.0, "argp": 0.0, "nu": 15.0},
         "attitude": quat([1, -3, 2], 20.0), "moment": [5.0, -2.0, 1.0]},
    ]
    aero = [
        {"label": "350 km circular equatorial, identity attitude",
         "elements": {"a": R_EARTH + 350e3, "e": 0.0, "i": 0.0, "raan": 0.0, "argp": 0.0, "nu": 0.0},
         "t": 0.0, "attitude": [1, 0, 0, 0], "area": 0.03, "drag_coefficient": 2.2,
         "center_of_pressure": [0.01, 0.0, 0.05]},
        {"label": "ISS-like 51.6 deg at 415 km, tilted 30 deg about (0,1,1)",
         "elements": {"a": R_EARTH + 415e3, "e": 0.0, "i": 51.6, "raan": 60.0, "argp": 0.0, "nu": 30.0},
         "t": 0.0, "attitude": quat([0, 1, 1], 30.0), "area": 1.2, "drag_coefficient": 2.2,
         "center_of_pressure": [0.05, -0.1, 0.3]},
        {"label": "near-polar e = 0.003, t = 700 s (246 km), tumbled 120 deg",
         "elements": {"a": R_EARTH + 260e3, "e": 0.003, "i": 90.0, "raan": 10.0, "argp": 45.0, "nu": 0.0},
         "t": 700.0, "attitude": quat([1, -1, 2], 120.0), "area": 0.5, "drag_coefficient": 2.0,
         "center_of_pressure": [-0.2, 0.15, 0.1]},
        {"label": "Explorer 1 orbit at perigee (358 km), tilted 45 deg about x",
         "elements": EXPLORER1, "t": 0.0, "attitude": quat([1, 0, 0], 45.0), "area": 0.0131,
         "drag_coefficient": 2.2, "center_of_pressure": [0.0, 0.0, -0.25]},
        {"label": "Explorer 1 orbit, t = 600 s (568 km, climbing), tilted 80 deg about (1,1,1)",
         "elements": EXPLORER1, "t": 600.0, "attitude": quat([1, 1, 1], 80.0), "area": 0.0131,
         "drag_coefficient": 2.2, "center_of_pressure": [0.02, 0.01, -0.25]},
        {"label": "retrograde 98 deg at 520 km, t = 3000 s, tilted 170 deg about (0.2,0.9,-0.3)",
         "elements": {"a": R_EARTH + 520e3, "e": 0.0012, "i": 98.0, "raan": 200.0, "argp": 120.0, "nu": 300.0},
         "t": 3000.0, "attitude": quat([0.2, 0.9, -0.3], 170.0), "area": 2.5, "drag_coefficient": 2.4,
         "center_of_pressure": [0.4, 0.0, -0.05]},
    ]
    srp = [
        {"label": "GEO at the 2024 June solstice, plate facing +y, identity attitude",
         "epoch": "2024-06-20T20:51:00Z", "t": 0.0,
         "elements": {"a": 42164e3, "e": 0.0, "i": 0.0, "raan": 0.0, "argp": 0.0, "nu": 0.0},
         "attitude": [1, 0, 0, 0], "area": 10.0, "normal": [0.0, 1.0, 0.0],
         "center_of_pressure": [0.2, 0.5, -0.3], "specular": 0.3, "diffuse": 0.2},
        {"label": "GEO, 2024-01-03 (perihelion) + 6 h, tilted 50 deg about (1,2,0)",
         "epoch": "2024-01-03T00:00:00Z", "t": 21600.0,
         "elements": {"a": 42164e3, "e": 0.0, "i": 0.0, "raan": 0.0, "argp": 0.0, "nu": 90.0},
         "attitude": quat([1, 2, 0], 50.0), "area": 10.0, "normal": [0.6, 0.0, 0.8],
         "center_of_pressure": [0.1, -0.4, 0.6], "specular": 0.5, "diffuse": 0.1},
        {"label": "sun-synchronous 700 km, 2021-03-20, plate tilted, dayside",
         "epoch": "2021-03-20T12:00:00Z", "t": 0.0,
         "elements": {"a": R_EARTH + 700e3, "e": 0.0, "i": 98.2, "raan": 0.0, "argp": 0.0, "nu": 0.0},
         "attitude": quat([0, 0, 1], 200.0), "area": 2.0, "normal": [-0.48, 0.6, 0.64],
         "center_of_pressure": [0.3, 0.1, 0.2], "specular": 0.0, "diffuse": 0.0},
        {"label": "Explorer 1 orbit, 2030-07-04 (near aphelion) + 1234 s, white diffuse plate",
         "epoch": "2030-07-04T00:00:00Z", "t": 1234.0, "elements": EXPLORER1,
         "attitude": quat([-1, 0.5, 0.2], 70.0), "area": 0.05, "normal": [0.0, 0.0, 1.0],
         "center_of_pressure": [0.0, 0.03, 0.4], "specular": 0.1, "diffuse": 0.8},
        {"label": "700 km, 2021-03-20, night side (deep in the umbra): zero torque",
         "epoch": "2021-03-20T12:00:00Z", "t": 0.0,
         "elements": {"a": R_EARTH + 700e3, "e": 0.0, "i": 98.2, "raan": 180.0, "argp": 0.0, "nu": 0.0},
         "attitude": [1, 0, 0, 0], "area": 2.0, "normal": [1.0, 0.0, 0.0],
         "center_of_pressure": [0.3, 0.1, 0.2], "specular": 0.2, "diffuse": 0.2},
        {"label": "GEO at the June solstice, the plate's back to the Sun: zero torque",
         "epoch": "2024-06-20T20:51:00Z", "t": 0.0,
         "elements": {"a": 42164e3, "e": 0.0, "i": 0.0, "raan": 0.0, "argp": 0.0, "nu": 0.0},
         "attitude": [1, 0, 0, 0], "area": 10.0, "normal": [0.0, -1.0, 0.0],
         "center_of_pressure": [0.2, 0.5, -0.3], "specular": 0.3, "diffuse": 0.2},
    ]
    return {"gravity_gradient": gg, "magnetic_dipole": md, "aerodynamic": aero, "solar_pressure": srp}


def main():
    wall0 = time.time()
    os.makedirs(RESULTS, exist_ok=True)
    from importlib.metadata import version
    evaluate = {"gravity_gradient": gravity_gradient, "magnetic_dipole": magnetic_dipole,
                "aerodynamic": aerodynamic, "solar_pressure": solar_pressure}
    out = {"basilisk": version("bsk"),
           "generated": time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime()),
           "conventions": "attitude: quaternion (w, x, y, z) mapping body to inertial (ECI) components, "
                          "as in polhode; sigma_bn is Basilisk's MRP of the same attitude. Elements in m "
                          "and degrees; epoch UTC; t in s after the epoch; torques N m in body axes.",
           "constants": {"mu": MU, "earth_radius": R_EARTH, "earth_rotation_rate": OMEGA_EARTH,
                         "igrf_reference_radius": IGRF_RADIUS, "solar_irradiance": SOLAR_IRRADIANCE,
                         "basilisk_solar_flux": BASILISK_SOLAR_FLUX, "astronomical_unit": AU},
           "effectors": {}}
    for kind, states in cases().items():
        rows = []
        for case in states:
            res = evaluate[kind](case)
            rows.append({"input": case, "basilisk": res})
            log(f"{kind}: {case['label']}: torque {np.array(res['torque'])}")
        out["effectors"][kind] = rows
    out["wall_seconds"] = time.time() - wall0
    with open(os.path.join(RESULTS, "basilisk_environment.json"), "w") as fh:
        json.dump(out, fh, indent=1)
        fh.write("\n")
    log("wrote results/basilisk_environment.json")


if __name__ == "__main__":
    main()
