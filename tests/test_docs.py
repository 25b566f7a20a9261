"""The user-facing docs stay runnable: the Python snippet of docs/api.md runs as printed against the current API
(and its numbers obey the thesis' dB references and the rigid-body mass law), and every `housingfe` command line
quoted in README.md and the docs a new user meets first parses with today's command line: sub-command, flags,
built-in scene and benchmark names, example scripts.  The examples themselves run in tests/test_examples.py."""
from __future__ import annotations

import functools
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]

# the docs a new user meets first; their fenced ``` blocks are checked line by line
FIRST_DOCS = ("README.md", "docs/api.md", "docs/outputs.md", "docs/CONTRIBUTING.md", "docs/cad.md",
              "docs/imported-meshes.md", "docs/correlation.md", "docs/reduction.md", "examples/README.md")


def _fenced_blocks(path: Path, language: str | None = None) -> list[str]:
    """The fenced code blocks of a markdown file (only those opened with ```<language> when given)."""
    blocks, current, lang = [], None, None
    for line in path.read_text().splitlines():
        if line.lstrip().startswith("```"):
            if current is None:
                current, lang = [], line.lstrip()[3:].strip()
            else:
                if language is None or lang == language:
                    blocks.append("\n".join(current))
                current = None
        elif current is not None:
            current.append(line)
    return blocks


# ------------------------------------------------------------------------------------- docs/api.md snippet
@pytest.mark.slow
def test_api_md_ten_lines_run_as_printed(tmp_path):
    """The "In ten lines" snippet, taken from docs/api.md verbatim, runs in a fresh process and prints <v^2> and
    TF_F at 100, 120, 140 Hz and L_WA.  Its 1 N rms force gives TF_F = L_v - L_F = 10 lg(<v^2>/v0^2) with
    v0 = 5e-8 m/s and F0 = 1 N (the thesis' references); and the free box (first elastic mode ~640 Hz) is
    mass-controlled there: v ~ F/(m omega), so <v^2> falls as 1/f^2 (the elastic modes' quasi-static part adds
    (f/f1)^2 ~ 2-5 %, within the 6 % allowed)."""
    (snippet,) = [b for b in _fenced_blocks(ROOT / "docs" / "api.md", "python") if "harmonic_response" in b]
    script = tmp_path / "ten_lines.py"
    script.write_text(snippet)
    env = dict(os.environ, PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    numbers = [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?", proc.stdout)]
    assert len(numbers) == 7, proc.stdout
    v2, tf, l_wa = np.array(numbers[:3]), np.array(numbers[3:6]), numbers[6]
    np.testing.assert_allclose(tf, 10 * np.log10(v2 / 5e-8 ** 2), atol=1e-6)
    f = np.array([100.0, 120.0, 140.0])
    np.testing.assert_allclose(v2[1:] / v2[:-1], (f[:-1] / f[1:]) ** 2, rtol=0.06)
    assert np.isfinite(l_wa)


# -------------------------------------------------------------------------------- quoted command lines
def _quoted_commands() -> list[tuple[str, int, str]]:
    """(doc, line number in its block list, command) for every `housingfe ...` line in the fenced blocks."""
    found = []
    for doc in FIRST_DOCS:
        for block in _fenced_blocks(ROOT / doc):
            for line in block.splitlines():
                text = line.strip().removeprefix("$ ")
                if re.match(r"(mpirun .*?)?(\.venv/bin/)?housingfe \S", text):
                    found.append((doc, len(found), text))
    return found


def _argv(command: str) -> list[str]:
    """The housingfe arguments of a quoted command: comment and launcher dropped; an optional `[--flag]` taken as
    given, an optional `[--opt VALUE]` (a placeholder value) left out."""
    command = command.split("  #")[0].split(" # ")[0]
    command = re.sub(r"\[(--[\w-]+)\]", r"\1", command)
    command = re.sub(r"\s\[--[^\]]+\]", "", command)
    words = shlex.split(command)
    return words[[i for i, w in enumerate(words) if w.endswith("housingfe")][0] + 1:]


COMMANDS = _quoted_commands()


def test_the_docs_quote_commands():
    docs = {doc for doc, _, _ in COMMANDS}
    assert {"README.md", "docs/cad.md", "docs/correlation.md", "docs/reduction.md"} <= docs, docs
    assert len(COMMANDS) >= 40, len(COMMANDS)


@pytest.mark.parametrize("doc,index,command", [pytest.param(*c, id=f"{c[0]}:{c[1]}") for c in COMMANDS])
def test_quoted_command_parses(doc, index, command):
    """argparse accepts it as written (sub-command and flags exist, values have the right type); a built-in
    scene or benchmark it names exists (placeholders: a .toml/.step/.uff path or an upper-case word)."""
    from housingfe.benchmarks._dispatch import available
    from housingfe.cli import build_parser
    from housingfe.scenefile import SCENE_DIR

    argv = _argv(command)
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:
        pytest.fail(f"{doc}: `{command}` does not parse (exit {exc.code})")
    if args.command == "bench":
        assert args.which in [*available(), "all"], f"{doc}: no benchmark {args.which!r}"
    scene = getattr(args, "scene", None)
    if isinstance(scene, str) and re.fullmatch(r"[a-z0-9-]+", scene):
        assert (SCENE_DIR / f"{scene}.toml").is_file(), f"{doc}: `{command}`: no built-in scene {scene!r}"


def test_quoted_example_scripts_exist():
    """`.venv/bin/python examples/<name>.py` in the first docs names a script that exists."""
    named = set()
    for doc in FIRST_DOCS:
        for block in _fenced_blocks(ROOT / doc):
            named |= set(re.findall(r"python (examples/[\w-]+\.py)", block))
    assert named, "no example quoted"
    assert not [n for n in sorted(named) if not (ROOT / n).is_file()]


def test_readme_builtin_scene_names_exist():
    """Every scene the README lists as built-in (`name`, and `name` (+`-suffix`) variants) is one."""
    from housingfe.scenefile import SCENE_DIR

    text = (ROOT / "README.md").read_text()
    start = text.index("Built-in housing scenes:")
    paragraph = text[start:text.index("\n\n", start)]
    names, base = [], None
    for token in re.findall(r"`([^`]+)`", paragraph):
        if not re.fullmatch(r"-?[a-z0-9][a-z0-9-]*", token) or token in ("housingfe", "kind"):
            continue
        if token.startswith("-"):
            names.append(base + token)
        else:
            base = token
            names.append(token)
    assert len(names) >= 20, names
    missing = [n for n in names if not (SCENE_DIR / f"{n}.toml").is_file()]
    assert not missing, f"README lists built-in scenes that do not exist: {missing}"


# ------------------------------------------------------------------------------------ links between the docs
def _markdown_files() -> list[Path]:
    """Every markdown file a reader follows links through: README, docs/, examples/, benchmarks/, tests' READMEs."""
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
            *sorted(p for d in ("examples", "benchmarks", "tests") for p in (ROOT / d).rglob("*.md"))]


def _slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped (hyphens kept), spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


@functools.lru_cache(maxsize=None)
def _headings(path: Path) -> tuple[str, ...]:
    """The markdown headings of a file, outside fenced blocks."""
    found, fenced = [], False
    for line in path.read_text().splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and (m := re.match(r"#{1,6}\s+(.*)", line)):
            found.append(m.group(1).strip())
    return tuple(found)


@functools.lru_cache(maxsize=None)
def _flat_lower(path: Path) -> str:
    """A file's text on one line, lower case (for bold lead-ins that wrap)."""
    return " ".join(path.read_text().split()).lower()


def _broken_links(path: Path) -> list[str]:
    """What in one markdown file points at nothing: a relative link [..](target#anchor) to a missing file or
    heading, a mention of docs/<name>.md that does not exist, and a quoted section (docs/<name>.md, "Title")
    that is neither a heading nor a bold lead-in of that file."""
    text, bad = path.read_text(), []
    here = path.relative_to(ROOT)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):            # http:, https:, mailto: are not ours to check
            continue
        file, _, anchor = target.partition("#")
        dest = (path.parent / file) if file else path
        if not dest.exists():
            bad.append(f"{here}: link ({target}): no file {file}")
        elif anchor and dest.suffix == ".md" and anchor not in {_slug(h) for h in _headings(dest)}:
            bad.append(f"{here}: link ({target}): no heading #{anchor} in {dest.relative_to(ROOT)}")
    for mention in re.findall(r"(?<![\w/.])(docs/[\w./-]+\.md)", text):
        if not (ROOT / mention).exists():
            bad.append(f"{here}: mentions {mention}, which does not exist")
    flat = " ".join(text.split())
    for mention, title in re.findall(r"(docs/[\w./-]+\.md),? (?:section )?[\"“]([^\"”]{3,80})[\"”]", flat):
        dest = ROOT / mention
        if not dest.exists():
            continue
        title = title.rstrip(".,").lower()
        if not any(title in h.lower() for h in _headings(dest)) and f"**{title}" not in _flat_lower(dest):
            bad.append(f'{here}: {mention}, "{title}": no such section')
    return bad


def test_links_between_the_docs_resolve():
    """Every relative link, docs/<name>.md mention and quoted section title of the markdown files points at a
    file and heading that exist (a renamed doc or section breaks the test, naming where it was referred to)."""
    files = _markdown_files()
    assert len(files) >= 40, files
    bad = [b for path in files for b in _broken_links(path)]
    assert not bad, "\n".join(bad)


def test_link_check_finds_a_broken_link(tmp_path, monkeypatch):
    """The checker itself: a missing file, a missing heading, a missing doc and a missing section are reported."""
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "a.md").write_text("# Title A\n\n**Bold lead.** text\n")
    page = tmp_path / "docs" / "b.md"
    page.write_text('[ok](a.md#title-a) [gone](c.md) [no](a.md#nothing) docs/missing.md; docs/a.md, "Bold lead"; '
                    'docs/a.md, "No such part"\n')
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    bad = _broken_links(page)
    assert len(bad) == 4, bad
    assert any("c.md" in b for b in bad) and any("#nothing" in b for b in bad)
    assert any("missing.md" in b for b in bad) and any("no such part" in b for b in bad)
