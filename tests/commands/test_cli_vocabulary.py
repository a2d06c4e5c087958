"""One command-line vocabulary: the ``motionlab`` parser walked, every sub-command and option.

Every sub-command has a description and every option a help text that shows its default; an
option name means one thing everywhere (the table ``VOCABULARY``: where the value goes, its type
or choices); every sub-command has ``-q/--quiet``; an old spelling kept for compatibility is a
hidden :class:`~motionlab.cli_args.DeprecatedAlias` that still works and says what replaced it.
"""

from __future__ import annotations

import argparse

import pytest

from motionlab import cli
from motionlab.cli_args import DeprecatedAlias, HelpFormatter
from motionlab.retargeting import terms


def _commands() -> dict[str, argparse.ArgumentParser]:
    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


COMMANDS = _commands()


def _options(command: str) -> list[argparse.Action]:
    """The command's options as ``--help`` lists them (no positionals, no -h, no deprecated aliases)."""
    return [
        a
        for a in COMMANDS[command]._actions
        if a.option_strings and not isinstance(a, (argparse._HelpAction, DeprecatedAlias))
    ]


def _kind(action: argparse.Action) -> str:
    """What an option takes: ``flag``, the name of its type function, or ``text``."""
    if action.nargs == 0:
        return "flag"
    return "text" if action.type in (None, str) else action.type.__name__


# option name -> (destination, kind, meaning). Names in PER_COMMAND_CHOICES pick among the
# command's own algorithms, so their choices differ by command.
VOCABULARY = {
    "--output": ("output", "text", "the file or folder the command writes"),
    "--force": ("force", "flag", "replace existing outputs"),
    "--quiet": ("quiet", "flag", "no progress bars or status lines"),
    "--fps": ("fps", "frame_rate", "frame rate, frames per second"),
    "--seed": ("seed", "seed", "random seed"),
    "--device": ("device", "text", "torch device"),
    "--checkpoint": ("checkpoint", "text", "the retargeting network's checkpoint file"),
    "--network": ("network", "text", "which retargeting network: auto, real or synthetic"),
    "--canonical": ("canonical", "flag", "reduce the rig to the canonical 22 joints"),
    "--keep-implausible": ("keep_implausible", "flag", "keep outputs that fail the plausibility check"),
    "--keep-misses": ("keep_misses", "flag", "write a graph-search path whose counts miss the request"),
    "--characters": ("characters", "text", "target characters given as rigs (expand)"),
    "--num-characters": ("num_characters", "positive_int", "how many synthetic characters (demo)"),
    "--root": ("root", "text", "root trajectory rule of retargeting (stride, hips, legs, contacts)"),
    "--gap-root": ("root", "text", "root path across a filled gap (fill-gaps)"),
    "--rest-from": ("rest_from", "text", "a take of the same rig whose standing pose serves that rig's files"),
    "--stop-loss": ("stop_loss", "non_negative", "the latent iteration stops when L_iter drops below it"),
    "--distance-threshold": ("threshold", "positive", "largest frame distance of a motion-graph transition"),
    "--delta": ("delta", "text", "Δ, the dropped-frame factor of fill-gaps"),
    "--scale": ("scale", "factor", "scale the whole target character (retarget)"),
    "--unit-scale": ("unit_scale", "positive", "BVH units to metres (view)"),
    "--steps": ("steps", "non_negative_int", "step limit of the latent iteration"),
    "--lr": ("lr", "positive", "Adam step of the latent iteration"),
    **{  # one per registered loss term of the latent iteration (motionlab.retargeting.terms)
        f"--{t.name.replace('_', '-')}-weight": (f"{t.name}_weight", "non_negative", f"weight of the term L_{t.name}")
        for t in terms.registered()
    },
    "--init": ("init", "text", "start of the latent iteration"),
    "--exact-rounds": ("exact_rounds", "non_negative_int", "exact Gauss-Newton rounds of the latent start"),
    "--train-steps": ("train_steps", "positive_int", "Adam steps of training"),
    "--method": ("method", "text", "the command's algorithm"),
    "--backend": ("backend", "text", "where the parallel work runs: this process or Ray (expand, graph-build)"),
    "--workers": ("workers", "positive_int", "how many parallel workers (Ray actors or CPUs, threads locally)"),
}
PER_COMMAND_CHOICES = {"--method"}
SAME_CHOICES = {
    "--root": ("stride", "hips", "legs", "contacts"),
    "--gap-root": ("stride", "hermite", "linear"),
    "--backend": ("local", "ray"),
    "--network": ("auto", "real", "synthetic"),
}
SYNTHETIC = {"train": "non_negative_int", "graph-build": "flag"}  # both: built-in synthetic clips instead of files

RENAMED = {  # (command, old spelling) -> new spelling
    ("retarget", "--threshold"): "--stop-loss",
    ("expand", "--threshold"): "--stop-loss",
    ("evaluate", "--threshold"): "--stop-loss",
    ("graph-build", "--threshold"): "--distance-threshold",
    ("fill-gaps", "--threshold"): "--delta",
    ("fill-gaps", "--factor"): "--delta",
    ("fill-gaps", "--root"): "--gap-root",
    ("view", "--scale"): "--unit-scale",
    ("view", "--out"): "--output",
    ("demo", "--out"): "--output",
    ("demo", "--characters"): "--num-characters",
    ("train", "--steps"): "--train-steps",  # one idea, two names: train's Adam steps
    ("train", "--lr"): "--train-lr",
}


def test_every_command_has_a_description_and_every_option_help_with_its_default():
    missing = []
    for name, parser in COMMANDS.items():
        if not (parser.description or "").strip():
            missing.append(f"{name}: no description")
        formatter = HelpFormatter(name)
        for action in parser._actions:
            if isinstance(action, (argparse._HelpAction, DeprecatedAlias)):
                continue
            if not (action.help or "").strip():
                missing.append(f"{name} {action.option_strings or action.dest}: no help")
                continue
            shown = action.default is not None and action.default is not False and action.default != []
            if action.option_strings and shown and "default" not in formatter._get_help_string(action):
                missing.append(f"{name} {action.option_strings}: default {action.default!r} not shown")
    assert not missing, "\n".join(missing)


def test_no_description_shows_a_docstring_section():
    """``run``'s docstring is the help text; its numpydoc sections (Raises, Returns) are the
    developers' and stay out of ``--help``."""
    leaked = [n for n, p in COMMANDS.items() if "---" in (p.description or "") or "Raises" in (p.description or "")]
    assert not leaked, leaked


def test_every_help_fits_the_terminal(monkeypatch):
    """``--help`` wraps every line, the description and epilog included, to the terminal's width."""
    monkeypatch.setenv("COLUMNS", "80")
    wide = [
        f"{n}: {line[:60]}..." for n, p in COMMANDS.items() for line in p.format_help().splitlines() if len(line) > 80
    ]
    assert not wide, wide


def test_every_command_has_quiet():
    for name in COMMANDS:
        strings = {s for a in _options(name) for s in a.option_strings}
        assert {"-q", "--quiet"} <= strings, name


def test_an_option_name_means_one_thing_across_commands():
    seen: dict[str, set] = {}
    for name in COMMANDS:
        for action in _options(name):
            long = next(s for s in reversed(action.option_strings) if s.startswith("--"))
            if long == "--synthetic":
                assert (action.dest, _kind(action)) == ("synthetic", SYNTHETIC[name]), name
                continue
            seen.setdefault(long, set()).add(name)
            if long not in VOCABULARY:
                continue
            dest, kind, meaning = VOCABULARY[long]
            assert (action.dest, _kind(action)) == (dest, kind), f"{name} {long}: not {meaning!r}"
            if long in SAME_CHOICES:
                assert tuple(action.choices) == SAME_CHOICES[long], f"{name} {long}"
    shared = {long for long, names in seen.items() if len(names) > 1}
    assert shared <= set(VOCABULARY), f"options in several commands missing from VOCABULARY: {shared - set(VOCABULARY)}"


def test_short_options_are_the_same_everywhere():
    shorts = {}
    for name in COMMANDS:
        for action in _options(name):
            for s in action.option_strings:
                if not s.startswith("--"):
                    long = next(x for x in action.option_strings if x.startswith("--"))
                    assert shorts.setdefault(s, long) == long, f"{name}: {s} is {long}, elsewhere {shorts[s]}"


def test_every_deprecated_alias_is_listed_and_points_to_a_visible_option():
    found = {}
    for name, parser in COMMANDS.items():
        visible = {s for a in _options(name) for s in a.option_strings}
        for action in parser._actions:
            if isinstance(action, DeprecatedAlias):
                (old,) = action.option_strings
                assert action.help == argparse.SUPPRESS
                assert action.new in visible, (name, old)
                found[(name, old)] = action.new
    assert found == RENAMED


@pytest.mark.parametrize(("command", "old"), sorted(RENAMED))
def test_a_deprecated_spelling_still_works_and_says_so(command, old, capsys):
    parser = COMMANDS[command]
    new_action = next(a for a in _options(command) if RENAMED[(command, old)] in a.option_strings)
    value = {"positive": "0.5", "non_negative": "0.5", "positive_int": "3"}.get(_kind(new_action), "x")
    if new_action.choices:
        value = list(new_action.choices)[-1]
    if new_action.dest == "delta":
        value = "3"
    positionals = [a for a in parser._actions if not a.option_strings and a.nargs not in ("?", "*")]
    argv = ["in.bvh"] * len(positionals) + [old, value]
    if any(a.required for a in _options(command)):
        argv += [s for a in _options(command) if a.required for s in (a.option_strings[0], "out.x")]
    args = parser.parse_args(argv)
    expected = new_action.type(value) if new_action.type else value
    assert getattr(args, new_action.dest) == expected
    assert f"{old} is deprecated here; use {RENAMED[(command, old)]}" in capsys.readouterr().err


def test_the_new_spelling_prints_no_note(capsys):
    args = COMMANDS["graph-build"].parse_args(["--synthetic", "-o", "g.mlgraph", "--distance-threshold", "0.025"])
    assert args.threshold == 0.025
    assert capsys.readouterr().err == ""
