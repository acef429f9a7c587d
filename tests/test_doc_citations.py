"""Every docs page cited in the code, the templates, the tests, benchmarks and examples exists.

The rule, kept simple so that it is exact:

- **A citation** is ``docs/`` followed by a path ending in ``.md`` (letters, digits, ``_``, ``-``
  and ``/``), not preceded by a letter, digit, ``/``, ``.`` or ``-``, anywhere in a text file
  (``.py``, ``.j2``, ``.toml``, ...) under ``src``, ``benchmarks``, ``examples`` or ``tests``
  (``__pycache__``, ``*.egg-info`` and this file, whose examples are synthetic, left out).
  The page must exist under the repository's ``docs``.
- **A named section** is a double-quoted text right after the path and a comma:
  ``docs/page.md, "Section"``. The quote may wrap onto the next lines of a comment or
  docstring: line breaks, the indentation after them and a leading ``#`` or ``#:`` count as one
  space, and an escaped quote ``\\"`` as a quote. It must be contained, ignoring case, in a
  heading of that page (a line starting with one to six ``#`` outside fenced code blocks;
  backticks and ``*`` of the heading removed). Anything else after the path (``, E3`` of the
  errata, ``: −14 %``, a ``#anchor``) is not a section name and is not checked.
"""

import re
from pathlib import Path

import pytest

HERE = Path(__file__).resolve()
ROOT = HERE.parent.parent
SCANNED = ("src", "benchmarks", "examples", "tests")
TEXT_SUFFIXES = {".py", ".j2", ".toml", ".css", ".md", ".txt", ".cfg", ".yaml", ".yml", ".html"}
CITATION = re.compile(r"(?<![\w/.-])docs/((?:[\w-]+/)*[\w-]+\.md)")
# What follows the path: the line breaks of a wrapped comment or docstring count as one space.
WRAP = re.compile(r"\s*\n\s*(?:#:?[ \t]*)?")
SECTION = re.compile(r'\A,\s*"([^"]+)"')
FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^#{1,6}\s+(.+?)\s*#*\s*$")


def headings(page: Path) -> list[str]:
    """Return the page's headings, lower case, without backticks and ``*``."""
    found, fenced = [], False
    for line in page.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            fenced = not fenced
        elif not fenced and (match := HEADING.match(line)):
            found.append(re.sub(r"[`*]", "", match.group(1)).lower())
    return found


def citations(text: str) -> list[tuple[int, str, str | None]]:
    """Return each citation of ``text``: (line, page path under docs/, section or None)."""
    found = []
    for match in CITATION.finditer(text):
        after = text[match.end() : match.end() + 400].replace('\\"', '"')
        section = SECTION.match(WRAP.sub(" ", after))
        name = " ".join(section.group(1).split()) if section else None
        found.append((text.count("\n", 0, match.start()) + 1, match.group(1), name))
    return found


def broken_citations(texts: dict[str, str], docs: Path) -> list[str]:
    """Return one line per citation in ``texts`` (name -> text) that ``docs`` does not hold."""
    problems = []
    for name, text in texts.items():
        for line, page, section in citations(text):
            path = docs / page
            if not path.is_file():
                problems.append(f"{name}:{line}: docs/{page} does not exist")
            elif section is not None and not any(section.lower() in h for h in headings(path)):
                problems.append(f'{name}:{line}: docs/{page} has no heading with "{section}"')
    return problems


def scanned(path: Path) -> bool:
    """Whether the scan reads ``path``: a text file, not generated, not this file."""
    generated = "__pycache__" in path.parts or any(p.endswith(".egg-info") for p in path.parts)
    return path.suffix in TEXT_SUFFIXES and path.is_file() and not generated and path != HERE


def scanned_texts() -> dict[str, str]:
    texts = {}
    for root in SCANNED:
        for path in sorted(filter(scanned, (ROOT / root).rglob("*"))):
            texts[str(path.relative_to(ROOT))] = path.read_text(encoding="utf-8")
    return texts


TEXTS = scanned_texts()


def test_every_cited_docs_page_and_section_exists():
    problems = broken_citations(TEXTS, ROOT / "docs")
    assert not problems, "\n".join(problems)


def test_the_scan_finds_the_citations():
    # A guard on the scan itself: the code cites the docs some 150 times, 20 with a section.
    found = [c for text in TEXTS.values() for c in citations(text)]
    assert len(found) > 100
    assert sum(section is not None for _, _, section in found) >= 10


def test_a_wrapped_section_name_is_read_whole():
    text = '# as measured (docs/validation3d.md, "The confusion\n        # matrix: predicted"): x'
    assert citations(text) == [(1, "validation3d.md", "The confusion matrix: predicted")]
    assert citations('help="(docs/steps.md, \\"Plans\\")"') == [(1, "steps.md", "Plans")]
    # Not a section name: the errata's item, a number; not a citation: another folder's docs.
    assert citations("docs/errata.md, E3; docs/steps.md: 2 %; out/docs/x.md") == [
        (1, "errata.md", None),
        (1, "steps.md", None),
    ]


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("see docs/no_such_page.md.", "docs/no_such_page.md does not exist"),
        ('docs/steps.md, "No such section"', 'docs/steps.md has no heading with "No such'),
    ],
)
def test_a_missing_page_or_section_fails(text, problem):
    (found,) = broken_citations({"synthetic.py": text}, ROOT / "docs")
    assert found.startswith("synthetic.py:1: ") and problem in found


def test_a_present_page_and_section_pass():
    text = 'docs/steps.md, "plans"; docs/conventions.md, "Outcome"; docs/c3d.md'
    assert broken_citations({"synthetic.py": text}, ROOT / "docs") == []
