"""Input validation: every rule rejects before anything is integrated, and the
error names the parameter, the offending value and what is allowed.

One parametrized case per rule.  Each case is (kwargs, parameter name, value text):
the message must contain the name and the value's text.
"""
import math

import numpy as np
import pytest

import ballc
from ballc import SceneError

nan, inf = math.nan, math.inf

#: (Scene keyword arguments, parameter named in the message, value shown in the message)
SCENE_CASES = {
    # positive finite mass, radius, ceiling height, moduli
    "mass zero": (dict(mass=0.0), "mass", "0.0"),
    "mass negative": (dict(mass=-1.0), "mass", "-1.0"),
    "mass nan": (dict(mass=nan), "mass", "nan"),
    "mass inf": (dict(mass=inf), "mass", "inf"),
    "mass string": (dict(mass="1.0"), "mass", "'1.0'"),
    "mass bool": (dict(mass=True), "mass", "True"),
    "mass complex": (dict(mass=1j), "mass", "1j"),
    "radius zero": (dict(radius=0.0), "radius", "0.0"),
    "radius negative": (dict(radius=-0.5), "radius", "-0.5"),
    "radius nan": (dict(radius=nan), "radius", "nan"),
    "ceiling negative": (dict(ceiling_height=-10.0), "ceiling_height", "-10.0"),
    "ceiling inf": (dict(ceiling_height=inf), "ceiling_height", "inf"),
    "ball modulus zero": (dict(ball_youngs_modulus=0.0), "ball_youngs_modulus", "0.0"),
    "ball modulus nan": (dict(ball_youngs_modulus=nan), "ball_youngs_modulus", "nan"),
    "plane modulus negative": (dict(plane_youngs_modulus=-2e10), "plane_youngs_modulus",
                               "-20000000000.0"),
    "plane modulus inf": (dict(plane_youngs_modulus=inf), "plane_youngs_modulus", "inf"),
    "regularization zero": (dict(friction_regularization_speed=0.0),
                            "friction_regularization_speed", "0.0"),
    "observer mass negative": (dict(observer_mass=-1e-4), "observer_mass", "-0.0001"),
    "gravity negative": (dict(gravity=-9.81), "gravity", "-9.81"),
    # ceiling height > 2 radius
    "ceiling equals diameter": (dict(ceiling_height=2.0, position=(0, 0, 1.0)),
                                "ceiling_height", "2.0"),
    "ceiling below diameter": (dict(ceiling_height=1.5, position=(0, 0, 0.75)),
                               "ceiling_height", "1.5"),
    # Poisson ratios in (-1, 0.5]
    "ball poisson -1": (dict(ball_poisson_ratio=-1.0), "ball_poisson_ratio", "-1.0"),
    "ball poisson 0.6": (dict(ball_poisson_ratio=0.6), "ball_poisson_ratio", "0.6"),
    "plane poisson -1.5": (dict(plane_poisson_ratio=-1.5), "plane_poisson_ratio", "-1.5"),
    "plane poisson 0.5000001": (dict(plane_poisson_ratio=0.5000001), "plane_poisson_ratio",
                                "0.5000001"),
    # c_tau in (0, 1]
    "c_tau zero": (dict(c_tau=0.0), "c_tau", "0.0"),
    "c_tau above one": (dict(c_tau=1.01), "c_tau", "1.01"),
    "c_tau nan": (dict(c_tau=nan), "c_tau", "nan"),
    # friction coefficient >= 0
    "mu negative": (dict(friction_coefficient=-0.1), "friction_coefficient", "-0.1"),
    "mu inf": (dict(friction_coefficient=inf), "friction_coefficient", "inf"),
    # mixture in [0, 1]
    "mixture negative": (dict(mixture=-0.01), "mixture", "-0.01"),
    "mixture above one": (dict(mixture=1.5), "mixture", "1.5"),
    # observer strictly inside the ball
    "observer on surface": (dict(observer_position=(1.0, 0.0, 0.0)), "observer_position",
                            "(1.0, 0.0, 0.0)"),
    "observer outside": (dict(observer_position=(0.8, 0.8, 0.0)), "observer_position",
                         "(0.8, 0.8, 0.0)"),
    "observer nan": (dict(observer_position=(nan, 0.0, 0.0)), "observer_position[0]", "nan"),
    # positive inertias satisfying the triangle inequality
    "inertia zero": (dict(inertia=(0.0, 0.4, 0.4)), "inertia", "(0.0, 0.4, 0.4)"),
    "inertia negative": (dict(inertia=(-0.4, 0.4, 0.4)), "inertia", "(-0.4, 0.4, 0.4)"),
    "inertia triangle": (dict(inertia=(0.1, 0.1, 0.3)), "inertia", "(0.1, 0.1, 0.3)"),
    "inertia nan": (dict(inertia=(0.4, nan, 0.4)), "inertia[1]", "nan"),
    "inertia length": (dict(inertia=(0.4, 0.4)), "inertia", "(0.4, 0.4)"),
    # finite initial state, 3 numbers per vector
    "position nan": (dict(position=(0.0, nan, 5.0)), "position[1]", "nan"),
    "velocity inf": (dict(velocity=(0.0, inf, 0.0)), "velocity[1]", "inf"),
    "angles nan": (dict(angles=(nan, 0.0, 0.0)), "angles[0]", "nan"),
    "angular velocity -inf": (dict(angular_velocity=(0.0, 0.0, -inf)),
                              "angular_velocity[2]", "-inf"),
    "velocity too long": (dict(velocity=(1.0, 2.0, 3.0, 4.0)), "velocity", "(1.0, 2.0, 3.0, 4.0)"),
    "velocity string": (dict(velocity="123"), "velocity", "'123'"),
    "velocity scalar": (dict(velocity=5.0), "velocity", "5.0"),
    # initial position not overlapping a plane
    "below the floor": (dict(position=(0.0, 0.0, -0.5)), "position", "(0.0, 0.0, -0.5)"),
    "below floor": (dict(position=(0.0, 0.0, -3.0)), "position", "(0.0, 0.0, -3.0)"),
    "above the ceiling": (dict(position=(0.0, 0.0, 10.0)), "position", "(0.0, 0.0, 10.0)"),
    # unknown tangential model, with a suggestion
    "tangential model typo": (dict(tangential_model="frictoin"), "tangential_model",
                              "'frictoin'"),
    "tangential model none": (dict(tangential_model=None), "tangential_model", "None"),
}


@pytest.mark.parametrize("kwargs, name, value", list(SCENE_CASES.values()),
                         ids=list(SCENE_CASES))
def test_invalid_scene_is_rejected_naming_parameter_and_value(kwargs, name, value):
    with pytest.raises(SceneError) as info:
        ballc.Scene(**kwargs)
    message = str(info.value)
    assert name in message and value in message, message
    assert "allowed" in message or "must" in message, message


def test_tangential_model_typo_suggests_the_right_name():
    with pytest.raises(SceneError, match="did you mean 'friction'"):
        ballc.Scene(tangential_model="frictoin")
    with pytest.raises(SceneError, match="did you mean 'dig-in'"):
        ballc.Scene(tangential_model="digin")


@pytest.mark.parametrize("make", [lambda: ballc.Scene(frictoin_coefficient=0.1),
                                  lambda: ballc.Scene.from_dict({"frictoin_coefficient": 0.1}),
                                  lambda: ballc.Scene().replace(frictoin_coefficient=0.1)],
                         ids=["Scene", "from_dict", "replace"])
def test_unknown_field_is_rejected_with_did_you_mean(make):
    with pytest.raises(SceneError) as info:
        make()
    message = str(info.value)
    assert "'frictoin_coefficient'" in message
    assert "did you mean 'friction_coefficient'" in message


def test_unknown_field_without_close_match_has_no_bogus_suggestion():
    with pytest.raises(SceneError) as info:
        ballc.Scene(zzzzzz=1)
    assert "'zzzzzz'" in str(info.value) and "did you mean" not in str(info.value)


def test_error_is_a_value_error():
    """Callers who catch ValueError keep working."""
    assert issubclass(SceneError, ValueError)


@pytest.mark.parametrize("kwargs", [
    dict(position=(0.0, 0.0, 1.0), velocity=(0.0, 0.0, -1.0)),   # touching the floor
    dict(position=(0.0, 0.0, 9.0), velocity=(0.0, 0.0, 1.0)),    # touching the ceiling
    dict(c_tau=1.0), dict(mixture=0.0), dict(mixture=1.0), dict(friction_coefficient=0.0),
    dict(ball_poisson_ratio=0.5), dict(ball_poisson_ratio=-0.99), dict(gravity=0.0),
    dict(observer_mass=0.0), dict(inertia=(0.2, 0.2, 0.4)),       # triangle equality
    dict(ceiling_height=2.0001, position=(0.0, 0.0, 1.00005)),
    dict(position=np.array([0.0, 0.0, 5.0]), velocity=[1, 2, 3]),  # any sequence of numbers
    dict(mass=np.float32(2.0), radius=2),
], ids=repr)
def test_boundary_values_are_accepted(kwargs):
    """Accepted, kept as given, and usable.  Oracles: Hertz's k0 = 4/3 E* sqrt(r),
    1/E* = (1 - nu_b^2)/E_b + (1 - nu_p^2)/E_p, by hand (the Poisson ratios at their
    limits among them); a 0.3-s run (the first contact included, for all but the
    steep throw) closes its energy balance -- kinetic + potential + springs + dissipated
    stays at its initial value -- to 1e-8 of the energy (measured <= 3e-11)."""
    scene = ballc.Scene(**kwargs)
    for name, value in kwargs.items():
        assert np.array_equal(np.asarray(getattr(scene, name), dtype=float),
                              np.asarray(value, dtype=float)), name
    inverse = ((1 - scene.ball_poisson_ratio ** 2) / scene.ball_youngs_modulus
               + (1 - scene.plane_poisson_ratio ** 2) / scene.plane_youngs_modulus)
    assert scene.hertz_stiffness == pytest.approx(4 / 3 / inverse * math.sqrt(scene.radius),
                                                  rel=1e-12)
    result = ballc.simulate(scene, 0.3)
    assert result.status == 0, result.message
    balance = result.energy["balance"]
    assert np.max(np.abs(balance - balance[0])) <= 1e-8 * (1 + abs(result.energy["total"][0]))


#: (simulate keyword arguments besides the scene, parameter named, value shown)
SIMULATE_CASES = {
    "t_end zero": (dict(t_end=0.0), "t_end", "0.0"),
    "t_end negative": (dict(t_end=-1.0), "t_end", "-1.0"),
    "t_end nan": (dict(t_end=nan), "t_end", "nan"),
    "t_end inf": (dict(t_end=inf), "t_end", "inf"),
    "t_end string": (dict(t_end="5"), "t_end", "'5'"),
    "rtol zero": (dict(t_end=1.0, rtol=0.0), "rtol", "0.0"),
    "rtol negative": (dict(t_end=1.0, rtol=-1e-6), "rtol", "-1e-06"),
    "rtol nan": (dict(t_end=1.0, rtol=nan), "rtol", "nan"),
    "rtol below 100 eps": (dict(t_end=1.0, rtol=1e-15), "rtol", "1e-15"),
    "atol zero": (dict(t_end=1.0, atol=0.0), "atol", "0.0"),
    "atol inf": (dict(t_end=1.0, atol=inf), "atol", "inf"),
    "atol wrong length": (dict(t_end=1.0, atol=[1e-8] * 5), "atol", "1e-08"),
    "atol negative entry": (dict(t_end=1.0, atol=[1e-8] * 12 + [-1.0]), "atol", "-1.0"),
    "method unknown": (dict(t_end=1.0, method="radau"), "method", "'radau'"),
    "max_step zero": (dict(t_end=1.0, max_step=0.0), "max_step", "0.0"),
    "max_step nan": (dict(t_end=1.0, max_step=nan), "max_step", "nan"),
    "t_eval beyond t_end": (dict(t_end=1.0, t_eval=[0.0, 2.0]), "t_eval", "2.0"),
    "t_eval decreasing": (dict(t_end=1.0, t_eval=[0.5, 0.2]), "t_eval", "0.5"),
    "t_eval negative": (dict(t_end=1.0, t_eval=[-0.1, 0.5]), "t_eval", "-0.1"),
    "t_eval 2-D": (dict(t_end=1.0, t_eval=[[0.1, 0.5]]), "t_eval", "[[0.1, 0.5]]"),
}


@pytest.mark.parametrize("kwargs, name, value", list(SIMULATE_CASES.values()),
                         ids=list(SIMULATE_CASES))
def test_invalid_simulate_option_is_rejected_before_integration(kwargs, name, value,
                                                                monkeypatch):
    def must_not_integrate(*args, **kw):
        raise AssertionError("integrated despite invalid input")

    monkeypatch.setattr(ballc._core, "drive", must_not_integrate)   # the C loop
    with pytest.raises(SceneError) as info:
        ballc.simulate(ballc.Scene(), **kwargs)
    message = str(info.value)
    assert name in message and value in message, message


def test_scene_must_be_a_scene():
    with pytest.raises(TypeError, match="Scene"):
        ballc.simulate({"mass": 1.0}, 1.0)


def test_per_state_atol_is_accepted():
    """A per-state atol is the error control's, state by state.  Oracles: the same value
    for every state is the scalar atol's run (another driver, the same steps: measured
    identical); each run is within 10 rtol of every state's size of a run at rtol =
    atol = 1e-12 (measured 1.7e-6 m/s at rtol 1e-6 over the seed's first contact), also
    with atol 1e-3 on the dissipated-work states alone (they feed nothing back: 3.6e-6),
    which is not what the loose value on every state gives (5e-5)."""
    names = ballc.STATE_NAMES
    mechanical = names.index("dissipated_normal")      # q, x, omega, v before it
    scene, t_end, rtol = ballc.Scene(), 0.5, 1e-6
    reference = ballc.simulate(scene, t_end, rtol=1e-12, atol=1e-12).y[:mechanical, -1]
    scalar = ballc.simulate(scene, t_end, rtol=rtol, atol=1e-9)
    each = ballc.simulate(scene, t_end, rtol=rtol, atol=np.full(len(names), 1e-9))
    loose = np.where(np.arange(len(names)) >= mechanical, 1e-3, 1e-9)
    partly = ballc.simulate(scene, t_end, rtol=rtol, atol=loose)
    assert each.status == scalar.status == partly.status == 0
    assert len(each.contacts) == 1
    assert np.max(np.abs(each.y[:, -1] - scalar.y[:, -1])) <= 1e-9
    bound = 10 * rtol * (1 + np.abs(reference))
    for run in (scalar, each, partly):
        assert np.all(np.abs(run.y[:mechanical, -1] - reference) <= bound)
    everywhere = ballc.simulate(scene, t_end, rtol=rtol, atol=1e-3)
    assert not np.all(np.abs(everywhere.y[:mechanical, -1] - reference) <= bound / 5)
