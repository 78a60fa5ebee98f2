"""``rigcad basis`` estimates its memory from the projector's resolution and the order before any
work, and refuses in one line naming the largest order (or projector) that fits: a 16384 x 16384
projector (the schema allows it) took 3.4 GB at order 0 and grows with every function."""

from __future__ import annotations

import pytest

from rigcad.cli.basis import (BASIS_BYTES_PER_PIXEL, BASIS_BYTES_PER_PIXEL_FUNCTION, BASIS_FIXED_BYTES,
                              check_basis_memory)
from rigcad.engine import ResourceError

GIB = 2 ** 30


def test_the_measured_runs_fit_their_estimates():
    """Each measured peak (MiB, the constants' comment) is under its estimate, and within 3x of it."""
    for (w, h), order, measured_mib in [((1024, 768), 0, 256), ((1024, 768), 4, 346), ((1024, 768), 8, 558),
                                        ((2048, 1536), 0, 290), ((2048, 1536), 4, 557), ((16384, 16384), 0, 3418)]:
        est = BASIS_FIXED_BYTES + w * h * (BASIS_BYTES_PER_PIXEL + BASIS_BYTES_PER_PIXEL_FUNCTION * (order + 1) ** 2)
        assert measured_mib * 2 ** 20 <= est < 3 * measured_mib * 2 ** 20, (w, h, order, est / 2 ** 20)


def test_the_largest_order_named_fits_and_the_next_does_not():
    with pytest.raises(ResourceError) as info:
        check_basis_memory((16384, 16384), 6, memory=24 * GIB)
    text = str(info.value)
    assert text.startswith("projector.resolution [16384, 16384] with --order 6: the basis would need about 102 GiB")
    assert text.endswith("the largest order that fits is 2"), text
    check_basis_memory((16384, 16384), 2, memory=24 * GIB)
    with pytest.raises(ResourceError):
        check_basis_memory((16384, 16384), 3, memory=24 * GIB)
    check_basis_memory((1024, 768), 12, memory=8 * GIB)  # the default projector at the largest order


def test_no_order_fits_names_the_largest_projector():
    with pytest.raises(ResourceError, match=r"even order 0 does not fit: the largest projector that fits has "):
        check_basis_memory((65536, 65536), 0, memory=24 * GIB)


def test_the_command_refuses_before_any_work(tmp_path, capsys, monkeypatch):
    from rigcad.cli.main import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "huge.yaml").write_text("extends: achutha2006\nprojector:\n  resolution: [16384, 16384]\n")
    # about 340 GiB: more than any machine this runs on
    assert main(["basis", "huge.yaml", "--order", "12", "--exports", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rigcad: error: projector.resolution [16384, 16384] with --order 12: the basis would need "
                          "about 34") and "\n" not in err, err
    assert not (tmp_path / "x").exists()
