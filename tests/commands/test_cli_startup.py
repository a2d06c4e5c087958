"""A command imports only the part of motionlab that owns it (graph-search must not wait for torch)."""

import subprocess
import sys

import pytest

pytestmark = pytest.mark.backend_free  # no numeric back end changes what it checks (CI runs it once)


def _modules_after(argv: list[str]) -> set[str]:
    code = (
        "import sys\nfrom motionlab import cli\n"
        f"try:\n    cli.main({argv!r})\nexcept SystemExit:\n    pass\n"
        "print(' '.join(sorted(sys.modules)))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return set(done.stdout.split())


@pytest.mark.parametrize("command", ["graph-info", "graph-search", "fill-gaps", "info"])
def test_a_light_command_does_not_import_torch(command, tmp_path):
    modules = _modules_after([command, str(tmp_path / "missing")])
    assert "torch" not in modules
    assert "motionlab.retargeting.cli" not in modules


def test_a_retargeting_command_still_finds_its_part():
    modules = _modules_after(["retarget", "--help"])
    assert "motionlab.retargeting.cli" in modules


def test_an_unknown_command_lists_every_command(capsys):
    from motionlab import cli

    with pytest.raises(SystemExit):
        cli.main(["no-such-command"])
    err = capsys.readouterr().err
    assert "'retarget'" in err and "'graph-search'" in err and "'info'" in err
