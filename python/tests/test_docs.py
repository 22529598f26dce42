"""Every python block of README.md, CONTRIBUTING.md and docs/*.md runs (issue 30).

tests/docs.rs runs the shell, TOML and C blocks; the python blocks need the package, which
CI builds into .venv after `cargo test`, so pytest runs them here. Each block runs as its own
script in a fresh temporary directory holding a copy of grammar/ (the blocks name
grammar/gripper.toml as a reader at the repository's root would), with the interpreter
running these tests. An annotation `<!-- docs-test: replace "A" with "B" -->` on the line
above a block runs a smaller variant, as in tests/docs.rs.
"""

import pathlib
import re
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGES = ["README.md", "CONTRIBUTING.md"] + sorted(
    str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")
)
FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})(.*)$")
REPLACE = re.compile(r'replace\s+"([^"]*)"\s+with\s+"([^"]*)"')


def python_blocks():
    """(page:line, code) of every python block, replacements applied."""
    found = []
    for page in PAGES:
        lines = (ROOT / page).read_text(encoding="utf-8").splitlines()
        i = 0
        while i < len(lines):
            m = FENCE.match(lines[i])
            if not m:
                i += 1
                continue
            indent, fence, info = len(m.group(1)), m.group(2), m.group(3).strip()
            note = lines[i - 1].strip() if i > 0 else ""
            start, body = i + 1, []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith(fence):
                line = lines[i]
                cut = len(line) - len(line.lstrip())
                body.append(line[min(cut, indent):])
                i += 1
            i += 1
            if info.split()[:1] != ["python"]:
                continue
            code = "\n".join(body) + "\n"
            if note.startswith("<!-- docs-test:"):
                for old, new in REPLACE.findall(note):
                    assert old in code, f"{page}:{start}: replace {old!r}: not in the block"
                    code = code.replace(old, new)
            found.append((f"{page}:{start}", code))
    return found


BLOCKS = python_blocks()


def test_the_docs_show_python():
    assert BLOCKS, "the docs show the Python package: at least one python block"


@pytest.mark.parametrize("where,code", BLOCKS, ids=[w for w, _ in BLOCKS])
def test_python_block_runs(where, code, tmp_path):
    shutil.copytree(ROOT / "grammar", tmp_path / "grammar")
    run = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, f"{where}: exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-4000:]}"
