"""scripts/macro_mpi_scaling.py: the command of a run on several ranks, each rank on its own threads."""
import os
import sys

import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import macro_mpi_scaling as M  # noqa: E402

CHILD = ["python", "macro_mpi_scaling.py", "--child", "scene.toml"]


def test_each_rank_gets_its_threads_the_last_for_the_rest():
    assert M.launch(CHILD, 1, (1, 2)) == CHILD
    assert M.launch(CHILD, 2) == ["mpiexec", "-n", "2"] + CHILD
    ranks = " ".join(M.launch(CHILD, 3, (1, 2))).split(" : ")
    assert [r.split(" python")[0] for r in ranks] == ["mpiexec -n 1 -env NGCONTACT_THREADS 1",
                                                      "-n 1 -env NGCONTACT_THREADS 2", "-n 1 -env NGCONTACT_THREADS 2"]
    assert all(r.endswith(" ".join(CHILD)) for r in ranks)


@pytest.mark.parametrize("threads", [["0"], ["1", "-2"]])
def test_rank_threads_below_one_are_refused_before_any_run(threads, tmp_path, capsys):
    with pytest.raises(SystemExit) as done:
        M.main([str(tmp_path / "out"), "--rank-threads", *threads])
    assert done.value.code == 2 and "integers >= 1" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
