"""Each contact's measured normal rebound ratio -v_n after / v_n before (issue 28, item 4).

Without gravity it is the restitution e the scene asked for (the law's e of an isolated
impact: the oracle is e itself, or for c_tau the Hunt-Crossley relation solved here);
under gravity it is not, and the contact table says so for the contacts where gravity's
impulse g t_c is more than GRAVITY_IMPULSE_SHARE of the exit normal speed.
"""
import csv
import math

import numpy as np
import pytest
from scipy.optimize import brentq

import ballc
from ballc.result import GRAVITY_IMPULSE_SHARE


def measured(contact):
    """-v_n after / v_n before of a contact, from its velocities (n: the plane's normal
    towards the ball, +z on the floor, -z on the ceiling)."""
    n = np.array([0.0, 0.0, 1.0 if contact.plane == "floor" else -1.0])
    return -float(contact.velocity_after @ n) / float(contact.velocity_before @ n)


def hunt_crossley_e(c_tau):
    """e of c_tau: chi (1 + e) = ln((1 + chi) / (1 - chi e)), chi = 3/2 (1 - c_tau)."""
    chi = 1.5 * (1 - c_tau)
    return brentq(lambda e: chi * (1 + e) - math.log((1 + chi) / (1 - chi * e)),
                  1e-12, 1.0 - 1e-15, xtol=1e-15)


WEIGHTLESS = dict(gravity=0.0, observer_mass=0.0, position=(0.0, 0.0, 3.0))
VERTICAL, OBLIQUE = (0.0, 0.0, -5.0), (0.5, -0.3, -5.0)
COMPLIANT_VISCOELASTIC = dict(tangential_model="compliant", normal_damping="viscoelastic")


@pytest.mark.parametrize("fields, e", [
    (dict(restitution=0.3, velocity=VERTICAL), 0.3),
    (dict(restitution=0.8, tangential_model="friction", velocity=OBLIQUE,
          angular_velocity=(2.0, 1.0, 3.0)), 0.8),
    (dict(c_tau=0.8, velocity=VERTICAL), hunt_crossley_e(0.8)),
    (dict(restitution=0.4, tangential_model="compliant", velocity=OBLIQUE), 0.4),
    (dict(**COMPLIANT_VISCOELASTIC, restitution=0.5, velocity=OBLIQUE), 0.5),
    (dict(**COMPLIANT_VISCOELASTIC, restitution=0.15, velocity=VERTICAL), 0.15),
], ids=["HC e 0.3", "HC e 0.8 friction oblique", "c_tau 0.8", "compliant e 0.4 oblique",
        "viscoelastic e 0.5 oblique", "viscoelastic e 0.15"])
def test_without_gravity_the_ratio_is_the_laws_e(fields, e):
    """(The seed's dig-in law is left out of the oblique impacts: its force points along
    the contact point's velocity at impact, normal part included, so it changes the
    normal rebound of an oblique impact -- by up to 5 % for the default mixture at 7 deg.)"""
    scene = ballc.Scene(**WEIGHTLESS, **fields)
    # floor, then the ceiling 8 m above at e 5 m/s
    t_end = 0.6 + 8.0 / (5.0 * e) + 0.5
    result = ballc.simulate(scene, t_end, rtol=1e-9, atol=1e-10)
    assert result.status == 0, result.message
    done = [c for c in result.contacts if np.isfinite(c.t_end)]
    assert {c.plane for c in done} == {"floor", "ceiling"}
    for contact in done:
        assert contact.rebound_ratio == pytest.approx(measured(contact), rel=1e-14)
        assert contact.rebound_ratio == pytest.approx(e, abs=2e-6)
    assert "gravity" not in result.contact_table()


def under_gravity(contact, g, t_last):
    """The criterion, computed here: gravity's impulse over the contact is more than
    GRAVITY_IMPULSE_SHARE of the exit normal speed, or the ball did not leave (at rest,
    or still in a contact over which g t already exceeds the impact speed)."""
    n = 1.0 if contact.plane == "floor" else -1.0
    if np.isfinite(contact.t_rest):
        return True
    if np.isfinite(contact.t_end):
        return g * contact.duration > GRAVITY_IMPULSE_SHARE * abs(contact.velocity_after[2] * n)
    return g * (t_last - contact.t_start) > abs(contact.velocity_before[2])


@pytest.fixture(scope="module")
def soft():
    """The default soft ball (E = 3 kPa, contacts of ~0.1 s) asked for e = 0.1 and 0.5:
    e = 0.1 rebounds once and then stays on the floor, rolling."""
    return {e: ballc.simulate(ballc.Scene(restitution=e), 3.0) for e in (0.1, 0.5)}


@pytest.mark.parametrize("e", [0.1, 0.5])
def test_the_soft_ball_under_gravity_is_flagged(soft, e):
    result = soft[e]
    assert result.status == 0
    flagged = [i for i, c in enumerate(result.contacts, 1)
               if under_gravity(c, result.scene.gravity, result.t[-1])]
    assert flagged, "the soft ball's contacts are long enough for gravity to matter"
    if e == 0.1:     # the rebound, and the contact it never leaves
        assert flagged == [1, 2] and math.isnan(result.contacts[1].t_end)
    assert result.gravity_affected_contacts() == [i - 1 for i in flagged]
    table = result.contact_table()
    note = [line for line in table.splitlines() if "gravity" in line]
    assert len(note) == 1, table
    assert f"e = {e:g}" in note[0]
    numbers = [int(k) for k in note[0].split(":")[0].replace("contacts", "").replace(
        "contact", "").replace(",", " ").split()]
    assert numbers == flagged, note[0]
    # and its measured ratio is indeed off the asked-for e (which is why it is flagged)
    first = result.contacts[flagged[0] - 1]
    if np.isfinite(first.t_end):
        assert abs(measured(first) - e) > 0.01 * e


def test_e_01_first_bounce_rebounds_well_below_e(soft):
    """The issue's figure: e = 0.1 on the soft ball rebounds from the floor at ~0.08
    (the table shows it; gravity takes the rest)."""
    first = soft[0.1].contacts[0]
    assert first.rebound_ratio == pytest.approx(measured(first), rel=1e-14)
    assert 0.03 < first.rebound_ratio < 0.09
    row = soft[0.1].contact_table().splitlines()[3]
    assert f"{first.rebound_ratio:.4f}" in row


def test_a_hard_ball_is_not_flagged():
    """A hard ball's short contacts under gravity: ratio = e to ~1e-3, no note."""
    result = ballc.simulate(ballc.Scene(restitution=0.5, ball_youngs_modulus=1e8,
                                        velocity=(0.0, 0.0, -10.0)), 1.5)
    done = [c for c in result.contacts if np.isfinite(c.t_end)]
    assert done
    for contact in done:
        assert not under_gravity(contact, 9.81, result.t[-1])
        assert contact.rebound_ratio == pytest.approx(0.5, abs=2e-3)
    assert result.gravity_affected_contacts() == []
    assert "gravity" not in result.contact_table()


def test_the_ratio_is_in_the_csv_the_dataframe_and_the_files(soft, tmp_path):
    result = soft[0.5]
    expected = [measured(c) if np.isfinite(c.t_end) else math.nan for c in result.contacts]
    result.contacts_csv(tmp_path / "c.csv")
    with open(tmp_path / "c.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert [float(r["rebound_ratio [1]"]) for r in rows] == pytest.approx(expected, rel=1e-14,
                                                                          nan_ok=True)
    frame = result.contacts_dataframe()
    assert frame["rebound_ratio"].to_numpy() == pytest.approx(expected, rel=1e-14, nan_ok=True)
    suffixes = [".npz"]
    try:
        import xarray  # noqa: F401
        suffixes.append(".nc")
    except ImportError:
        pass
    for suffix in suffixes:
        result.save(tmp_path / f"r{suffix}")
        again = ballc.load(tmp_path / f"r{suffix}")
        assert [c.rebound_ratio for c in again.contacts] == pytest.approx(expected, rel=1e-14,
                                                                          nan_ok=True)
    with np.load(tmp_path / "r.npz") as data:   # stored for readers of the file itself
        assert data["contact_rebound_ratio"] == pytest.approx(expected, rel=1e-14, nan_ok=True)


def test_a_contact_that_starts_at_rest_has_no_ratio():
    """A scene starting in contact without approach speed: no ratio (NaN), no error."""
    result = ballc.simulate(ballc.Scene(position=(0.0, 0.0, 0.999), velocity=(0.0, 0.0, 0.0)),
                            0.05)
    assert result.contacts and math.isnan(result.contacts[0].rebound_ratio)
    result.contact_table()
