"""Kharaz, Gorham & Salman (2001): 5 mm alumina (Al2O3) spheres on a soda-lime glass
anvil at 3.9 m/s, incident angle from the normal 0-60 degrees.

A. H. Kharaz, D. A. Gorham, A. D. Salman, "An experimental study of the elastic rebound
of spheres", Powder Technology 120(3):281-291, 2001, doi:10.1016/S0032-5910(01)00283-2.

Provenance.  The measured points were read off the paper's figures by the Lethe developers
and are tabulated in chaos-polymtl/lethe, examples/dem/3d-oblique-wall-impact/
oblique_wall_impact_postprocessing.py (commit 255b5192 of the stored copy); they are copied
here unchanged.  The inputs are MFIX's DEM05 verification case (tests/dem/DEM05/mfix.dat,
J. Musser 2014, stored copy CurtinIDS/mfix commit aa5da900; Hertzian run arguments in
the same folder's runtests.sh) and Lethe's postprocessing (incident speed 3.9 m/s).

Definitions (Lethe's): angles are measured from the plane's normal; the tangential
restitution is v_t'/v_t of the centre; the angular velocity is |omega| after the impact
(rad/s); the rebound angle is atan(v_t'/v_n') (degrees).
"""

# --- inputs (MFIX DEM05) ---------------------------------------------------------------
DIAMETER = 5.0e-3            # m, D_p0(1)
DENSITY = 4.0e3              # kg/m^3, RO_s0(1)
BALL_YOUNGS_MODULUS = 380.0e9   # Pa, E_YOUNG(1)
BALL_POISSON_RATIO = 0.23       # V_POISSON(1)
WALL_YOUNGS_MODULUS = 70.0e9    # Pa, Ew_YOUNG (soda-lime glass)
WALL_POISSON_RATIO = 0.25       # Vw_POISSON
FRICTION_COEFFICIENT = 0.092    # MEW_W, the nominal particle-wall friction
NORMAL_RESTITUTION = 1.0        # DES_EN_WALL_INPUT (MFIX runs the case elastic)
LINEAR_KT_OVER_KN = 1.48 / 1.72  # KT_W_FAC of MFIX's linear-spring run
SPEED = 3.9                  # m/s, incident speed (Lethe's postprocessing)

# --- measurements (Kharaz et al. 2001, as tabulated by Lethe) ---------------------------
# incident angle (deg) -> tangential restitution v_t'/v_t
TANGENTIAL_RESTITUTION_ANGLE = [1.84, 3.703, 9.496, 20.012, 30.127, 39.382, 49.694, 60.02]
TANGENTIAL_RESTITUTION = [0.79344, 0.74533, 0.67257, 0.59691, 0.68756, 0.77148, 0.84761,
                          0.90142]
# incident angle (deg) -> angular velocity after the impact (rad/s)
ANGULAR_VELOCITY_ANGLE = [6.143, 10.991, 21.251, 31.157, 39.143, 50.348, 60.328]
ANGULAR_VELOCITY = [136.18, 265.69, 577.65, 612.88, 595.49, 453.21, 382.09]
# incident angle (deg) -> rebound angle (deg)
REBOUND_ANGLE_INCIDENT = [0.016, 2.15, 4.096, 9.826, 20.567, 30.29, 39.535, 49.747, 60.208]
REBOUND_ANGLE = [0.074, 1.733, 2.962, 6.518, 12.208, 21.67, 32.613, 45.125, 57.474]

SOURCES = {
    "measurements": "chaos-polymtl/lethe examples/dem/3d-oblique-wall-impact/"
                    "oblique_wall_impact_postprocessing.py (digitised from Kharaz, Gorham "
                    "& Salman 2001, Powder Technol. 120:281-291)",
    "inputs": "MFIX tests/dem/DEM05/mfix.dat (CurtinIDS/mfix copy)",
}
