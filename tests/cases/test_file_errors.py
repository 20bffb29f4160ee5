"""Every way a case file can be unreadable is a CaseError that says why, never a raw error."""

from __future__ import annotations

import pytest

from pymoo_rail.cases import case_path, load_case
from pymoo_rail.model import CaseError

TEXT = case_path("metro-a").read_text(encoding="utf-8")


def _write(tmp_path, raw: bytes):
    path = tmp_path / "case.toml"
    path.write_bytes(raw)
    return path


def _refused(tmp_path, raw: bytes) -> str:
    with pytest.raises(CaseError) as raised:
        load_case(_write(tmp_path, raw))
    assert "case.toml" in str(raised.value)
    return str(raised.value)


def test_a_utf8_byte_order_mark_is_skipped(tmp_path):
    assert load_case(_write(tmp_path, b"\xef\xbb\xbf" + TEXT.encode())) == load_case("metro-a")


def test_latin1_utf16_and_binary_files_are_named(tmp_path):
    text = TEXT.replace('name = "metro-a"', 'name = "Großräschen"')
    assert "not UTF-8" in _refused(tmp_path, text.encode("latin-1", errors="replace"))
    assert "UTF-16" in _refused(tmp_path, text.encode("utf-16"))
    assert "binary" in _refused(tmp_path, bytes(range(256)) * 4)


def test_deeply_nested_toml_is_refused(tmp_path):
    assert "not valid TOML" in _refused(tmp_path, b"x = " + b"[" * 100_000 + b"]" * 100_000)


def test_an_unreadable_path_is_named(tmp_path):
    (tmp_path / "dir.toml").mkdir()
    with pytest.raises(CaseError, match="dir.toml"):
        load_case(tmp_path / "dir.toml")
