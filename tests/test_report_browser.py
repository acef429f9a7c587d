"""The report as a reader sees it: a non-default body rendered in headless Chromium.

Run by ``make report-check`` (pytest marker ``browser``; it installs Debian's Chromium when it
is missing): the report of a 45 kg body whose legs (0.72 m) are longer than its CoM is high
(0.70 m), a screenshot of the page and its DOM after the browser ran it. Skipped where no
Chromium is installed.
"""

import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.browser

BODY = ["--mass", "45", "--com-height", "0.7", "--leg-length", "0.72"]
OUT = Path(__file__).resolve().parents[1] / "out" / "report-check"
# The flags Debian's Chromium needs on a machine with no network and no screen (as root).
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
]
WIDTH, HEIGHT = 1400, 2400


def chromium() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        pytest.skip("no Chromium installed (make report-check installs Debian's)")
    return found


class Sections(HTMLParser):
    """The text of the verdict box, and of each top-level ``<section id=...>``."""

    def __init__(self) -> None:
        super().__init__()
        self.verdict, self.verdict_links = "", []
        self.sections: dict[str, str] = {}
        self._in_verdict = 0
        self._section: str | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "p" and attrs.get("class") == "verdict":
            self._in_verdict = 1
        elif self._in_verdict and tag == "a":
            self.verdict_links.append(attrs.get("href", ""))
        if tag == "section" and attrs.get("id"):
            self._section = attrs["id"]
            self.sections[self._section] = ""

    def handle_endtag(self, tag):
        if tag == "p":
            self._in_verdict = 0
        if tag == "section":
            self._section = None

    def handle_data(self, data):
        if self._in_verdict:
            self.verdict += data
        if self._section is not None:
            self.sections[self._section] += data + " "  # table cells apart


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    browser = chromium()
    shutil.rmtree(OUT, ignore_errors=True)
    done = subprocess.run(
        [sys.executable, "-m", "pushrecovery", "report", *BODY, "--out", str(OUT)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    index = OUT / "index.html"
    profile = tmp_path_factory.mktemp("chromium")
    common = [browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}"]
    shot = OUT / "screenshot.png"
    subprocess.run(
        [*common, f"--window-size={WIDTH},{HEIGHT}", f"--screenshot={shot}", index.as_uri()],
        capture_output=True,
        timeout=120,
        check=True,
    )
    dom = subprocess.run(
        [*common, "--dump-dom", index.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    return shot, dom


def test_the_screenshot_shows_a_page(page):
    from matplotlib.image import imread

    shot, _ = page
    image = imread(shot)
    assert image.shape[:2] == (HEIGHT, WIDTH)
    # A blank or unstyled page has a handful of colours; text, tables and figures thousands.
    colours = np.unique((image[..., :3] * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 500


def test_every_section_is_computed_or_named_in_the_verdict(page):
    _, dom = page
    parsed = Sections()
    parsed.feed(dom)
    assert parsed.verdict.startswith("Verdict.")
    expected = {
        "bounds", "map", "plane", "steps", "figures", "analytic", "planar", "sweep", "mujoco",
        "biped", "critical", "filmstrips", "humanoid3d",
    }  # fmt: skip
    assert expected <= set(parsed.sections)
    failed = {k for k, text in parsed.sections.items() if "could not be computed" in text}
    named = {link.removeprefix("#") for link in parsed.verdict_links}
    assert failed <= named, f"sections failed but the verdict box is silent: {failed - named}"
    # This body runs everything: its legs no longer stop the MuJoCo biped.
    assert failed == set()
    # The body the flags asked for, with units, in the parameter table.
    bounds = re.sub(r"\s+", " ", parsed.sections["bounds"])
    assert "leg_length 0.72 m" in bounds and "mass 45 kg" in bounds
