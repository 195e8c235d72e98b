"""The README keeps its promises: two set-up commands, CI runs the test one, the reference is current."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def readme():
    with open(os.path.join(ROOT, "README.md")) as fh:
        return fh.read()


def setup_commands():
    section = readme().split("## Set up on a fresh machine", 1)[1].split("\n## ", 1)[0]
    return [line.strip() for line in section.splitlines() if line.startswith("    ")]


def test_exactly_two_setup_commands_and_ci_runs_the_test_one():
    cmds = setup_commands()
    assert len(cmds) == 2, cmds
    main_job, tests = cmds
    assert "ngcontact run" in main_job
    assert "pytest" in tests
    with open(os.path.join(ROOT, ".ci", "run")) as fh:
        assert tests in fh.read(), "the CI script must run the README's test command verbatim"


def test_main_job_scene_exists_and_is_valid():
    from ngcontact.scene import loader as scene
    main_job = setup_commands()[0]
    path = re.search(r"ngcontact run (\S+)", main_job).group(1)
    scene.load(os.path.join(ROOT, path))


def test_scene_reference_is_current():
    script = os.path.join(ROOT, "scripts", "update_readme_reference.py")
    rc = subprocess.run([sys.executable, script, "--check"], cwd=ROOT).returncode
    assert rc == 0, "README scene reference is stale: run python scripts/update_readme_reference.py"
