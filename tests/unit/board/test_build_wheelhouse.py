"""The wheelhouse script's choices that need no network: what the board gets, and which
wheels a Raspberry Pi OS / Debian bookworm board (aarch64, CPython 3.11) can install."""

from __future__ import annotations

from board.build_wheelhouse import board_requirements, sizes_per_package, wheel_fits_board

EXPORTED = """\
annotated-doc==0.0.7
colorama==0.4.6 ; sys_platform == 'win32'
iceoryx2==0.10.0
numpy==2.4.6 ; python_full_version < '3.12'
numpy==2.5.5 ; python_full_version >= '3.12'
pymavlink==2.4.50
"""


def test_the_board_gets_its_own_pins_and_iceoryx2_is_built() -> None:
    download, built = board_requirements(EXPORTED)
    assert download == ["annotated-doc==0.0.7", "numpy==2.4.6", "pymavlink==2.4.50"]
    assert built == ["iceoryx2==0.10.0"]


def test_bookworm_installs_old_manylinux_aarch64_and_pure_wheels() -> None:
    fits = [
        "numpy-2.4.6-cp311-cp311-manylinux_2_27_aarch64.manylinux_2_28_aarch64.whl",
        "fastcrc-0.5.0-cp311-cp311-manylinux_2_17_aarch64.manylinux2014_aarch64.whl",
        "psutil-7.2.2-cp36-abi3-manylinux2014_aarch64.manylinux_2_17_aarch64.whl",
        "iceoryx2-0.10.0-cp38-abi3-manylinux_2_28_aarch64.whl",
        "pyserial-3.5-py2.py3-none-any.whl",
    ]
    assert all(wheel_fits_board(w) for w in fits)


def test_newer_glibc_other_cpus_and_other_pythons_are_refused() -> None:
    unfit = [
        "iceoryx2-0.10.0-cp38-abi3-manylinux_2_34_x86_64.whl",  # what PyPI has
        "numpy-2.4.6-cp311-cp311-manylinux_2_39_aarch64.whl",  # trixie's glibc, not bookworm's
        "numpy-2.4.6-cp312-cp312-manylinux_2_28_aarch64.whl",
        "lxml-6.1.3-cp311-cp311-musllinux_1_2_aarch64.whl",
        "psutil-7.2.2-cp36-abi3-linux_armv7l.whl",
    ]
    assert not any(wheel_fits_board(w) for w in unfit)


def test_sizes_are_summed_per_package_largest_first(tmp_path) -> None:
    (tmp_path / "numpy-2.4.6-cp311-cp311-manylinux_2_28_aarch64.whl").write_bytes(b"x" * 300)
    (tmp_path / "pyserial-3.5-py2.py3-none-any.whl").write_bytes(b"x" * 10)
    (tmp_path / "pyserial-3.4-py2.py3-none-any.whl").write_bytes(b"x" * 5)
    assert sizes_per_package(tmp_path) == [("numpy", 300), ("pyserial", 15)]
