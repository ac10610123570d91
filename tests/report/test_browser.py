"""Finding the Chromium that reports are drawn in (no browser needed for these)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from seminspect.core.errors import SeminspectError
from seminspect.report import browser


def test_the_chromium_named_by_the_environment_comes_first(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mine = tmp_path / "my-chromium"
    mine.write_text("#!/bin/sh\n")
    monkeypatch.setenv(browser.CHROMIUM_ENV, str(mine))
    assert browser.find_chromium() == str(mine)


def test_without_the_environment_it_is_debians_or_one_on_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(browser.CHROMIUM_ENV, str(tmp_path / "absent"))
    expected = "/usr/bin/chromium" if Path("/usr/bin/chromium").is_file() else None
    expected = expected or shutil.which("chromium") or shutil.which("chromium-browser")
    assert browser.find_chromium() == expected


def test_no_chromium_is_one_line_that_says_how_to_get_one(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(browser, "find_chromium", lambda: None)
    with pytest.raises(SeminspectError, match=r"^no Chromium found: apt-get install chromium"):
        browser.require_chromium()
