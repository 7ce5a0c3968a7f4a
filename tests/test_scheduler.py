"""``--scheduler`` / ``client=``: an address where no Dask scheduler answers is said up
front, in one line naming the option, the value and what is allowed, within a short
connect timeout, and nothing is written."""
import pytest

import ballc
from test_cli import assert_one_line_error, run_ballc

pytest.importorskip("distributed")

#: Port 1 (tcpmux) on this machine: nothing listens there; "nonsense": no port at all.
NO_SCHEDULER = ["tcp://127.0.0.1:1", "nonsense"]


@pytest.mark.parametrize("address", NO_SCHEDULER)
def test_a_bad_scheduler_is_one_line_and_no_folder(tmp_path, address):
    """Issue 28, item 6: a bad --scheduler waited distributed's 30-s connect timeout,
    then left an empty output folder (and a traceback-free but late error)."""
    (tmp_path / "s.toml").write_text("t_end = 0.2\n[parameters]\nmixture = [0.0, 0.5]\n")
    done = run_ballc("sweep", "s.toml", "--scheduler", address, "--out", "out",
                     cwd=tmp_path)
    assert_one_line_error(done, "--scheduler", repr(address), "tcp://host:8786")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("address", NO_SCHEDULER)
def test_a_bad_client_address_names_client(address):
    with pytest.raises(ValueError, match=r"client = .*is not allowed.*tcp://host:8786"):
        ballc.sweep(ballc.Scene(), {"mixture": [0.0, 0.5]}, 0.2, client=address)
