"""The docs site's own promises: short pages, no lab notes, a landing page whose code runs.

The site is built with warnings as errors by ``make docs`` (a prerequisite of ``make test``);
the guides' code runs in tests/test_guides.py and the README's in tests/test_readme.py.
"""

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)
# Words of a lab notebook, not of a manual (issue 39's grep).
LAB_NOTES = re.compile(r"session|this morning|yesterday|helper-", re.I)


def python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_page_is_at_most_400_lines(page):
    assert len(page.read_text().splitlines()) <= 400


def test_readme_is_at_most_200_lines():
    assert len((ROOT / "README.md").read_text().splitlines()) <= 200


@pytest.mark.parametrize("page", [*PAGES, ROOT / "README.md"], ids=lambda p: p.name)
def test_no_lab_notes(page):
    hits = [line for line in page.read_text().splitlines() if LAB_NOTES.search(line)]
    assert not hits, hits


def test_landing_page_example_runs_and_prints_what_it_says(capsys):
    (block,) = python_blocks(DOCS / "index.md")
    exec(compile(block, "docs/index.md", "exec"), {})
    promised = re.search(r"# prints: (.*)", block)
    assert promised is not None
    assert capsys.readouterr().out.strip() == promised.group(1).strip()


def test_lab_note_check_can_fail():
    assert LAB_NOTES.search("re-measured in the second Session")


@pytest.mark.parametrize("page", [p for p in PAGES if "```toml" in p.read_text()], ids=str)
def test_parameter_files_shown_load(page, tmp_path):
    from pushrecovery import load_params

    for i, block in enumerate(re.findall(r"```toml\n(.*?)```", page.read_text(), flags=re.S)):
        path = tmp_path / f"{i}.toml"
        path.write_text(block)
        load_params(file=path)
