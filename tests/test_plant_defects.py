"""benchmarks/plant_defects.py's table still applies to the tree: every planted defect's
pattern is found as many times as it expects, and every test it names exists.  (The
benchmark itself plants, rebuilds and runs the suite: minutes, not part of the suite.)
A refactoring that moves a pattern must update the entry, so that no planted defect
turns into a silent no-op."""
from benchmarks import plant_defects
from benchmarks.plant_defects import DEFECTS, Defect, problems_with


def test_every_planted_defect_applies_to_the_tree():
    assert problems_with(DEFECTS) == []


def test_every_defect_names_the_tests_that_catch_it():
    assert all(defect.tests for defect in DEFECTS)


def test_a_stale_pattern_or_a_missing_test_is_reported(tmp_path):
    (tmp_path / "a.py").write_text("x = 1\nx = 1\n")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_a.py").write_text("def test_one():\n    pass\n")
    good = Defect("good", "a.py", "x = 1\n", "x = 2\n", tests=("tests/test_a.py::test_one",),
                  count=2)
    assert problems_with([good], tmp_path) == []
    once = Defect("once", "a.py", "x = 1\n", "x = 2\n", tests=("tests/test_a.py::test_one",))
    missing = Defect("missing", "a.py", "y = 1\n", "y = 2\n", count=2,
                     tests=("tests/test_a.py::test_two",))
    found = problems_with([once, missing], tmp_path)
    assert any("'once': pattern found 2 times" in p for p in found)
    assert any("'missing': pattern found 0 times" in p for p in found)
    assert any("tests/test_a.py::test_two does not exist" in p for p in found)
    assert plant_defects.Defect("g", "codegen/contact.py", "a", "b").regenerate


def test_a_failure_is_told_apart_from_a_timeout_and_a_crash(tmp_path):
    """How a pytest run's junit XML is read: an assertion, another exception, a
    pytest-timeout, and a run that never wrote its XML."""
    def junit(message, tag="failure"):
        path = tmp_path / f"{abs(hash(message))}.xml"
        path.write_text(f'<testsuites><testsuite><testcase classname="tests.test_x" name="test_a"/>'
                        f'<testcase classname="tests.test_x" name="test_b[1]"><{tag} '
                        f'message="{message}">trace</{tag}></testcase></testsuite></testsuites>')
        return path
    outcome = plant_defects.outcome_of(junit("AssertionError: assert 1 == 2"), 1, "")
    assert (outcome.kind, outcome.test, outcome.passed, outcome.caught) == (
        "assertion", "tests/test_x.py::test_b[1]", 1, True)
    assert plant_defects.outcome_of(junit("Failed: DID NOT RAISE"), 1, "").kind == "assertion"
    error = plant_defects.outcome_of(junit("ValueError: bad"), 1, "")
    assert error.kind == "error" and error.caught
    timeout = plant_defects.outcome_of(junit("Failed: Timeout (&gt;300.0s) from pytest-timeout."),
                                       1, "")
    assert timeout.kind == "timeout" and not timeout.caught
    assert plant_defects.outcome_of(tmp_path / "none.xml", None, "").kind == "timeout"
    assert plant_defects.outcome_of(tmp_path / "none.xml", -11, "Segmentation fault").kind \
        == "crash"
