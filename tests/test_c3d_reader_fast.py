"""The C3D reader's fast path (``gaitval.io.c3d_format._frames_only``): for a file of Intel
floats with nothing but point frames, ezc3d reads the file cut to its first frame and numpy
the frames.  What the reader gets must be what ezc3d gives for the whole file: every array
bit for bit, with the same dtype, shape and memory layout (sums downstream follow it), and
every parameter and header value."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.io.c3d import read_c3d, write_c3d
from gaitval.io.c3d_format import _ezc3d_child, _open_ezc3d, _precheck


def assert_same(a, b, where=""):
    """Deep equality of what ``_extract`` returns: arrays by their bytes and layout."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), where
        for k in a:
            assert_same(a[k], b[k], f"{where}/{k}")
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray), where
        layout = [(n, st) for n, st in zip(a.shape, a.strides) if n > 1]   # size-1 axes
        assert (a.dtype, a.shape, layout) == (              # have no meaningful stride
            b.dtype, b.shape, [(n, st) for n, st in zip(b.shape, b.strides) if n > 1]), where
        assert a.tobytes() == b.tobytes(), where
    elif isinstance(a, (list, tuple)):
        assert type(a) is type(b) and len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    else:
        assert type(a) is type(b) and a == b, (where, a, b)


def both_ways(path: Path):
    pre = _precheck(path, None)
    return pre["frames_only"], _open_ezc3d(path, None, pre), _ezc3d_child(path, path, None)


@pytest.mark.parametrize("n_frames, n_markers, first_frame, prefix, with_events", [
    (1, 1, 1, None, False),
    (33, 3, 5, "S1", True),
    (1000, 9, 1, None, True),
    (40000, 3, 1, "S1", False),     # POINT:FRAMES stored as int16 -25,536
    (60000, 9, 1, None, False),     # an ultrasonic trial of the default study
    (65535, 1, 1, None, False),
])
def test_fast_reader_gives_what_ezc3d_gives(tmp_path, n_frames, n_markers, first_frame,
                                            prefix, with_events):
    rng = np.random.default_rng(n_frames)
    xyz = rng.normal(scale=2.0, size=(n_frames, n_markers, 3))
    xyz[rng.random((n_frames, n_markers)) < 0.03] = np.nan             # gaps
    events = pd.DataFrame({"context": ["Left"], "label": ["Foot Strike"], "t_s": [0.01]}) \
        if with_events else None
    p = write_c3d(tmp_path / "t.c3d", [f"M{i}" for i in range(n_markers)], xyz, 200.0,
                  events=events, first_frame=first_frame, subject_prefix=prefix)
    layout, fast, whole = both_ways(p)
    assert layout is not None                                   # the fast path was taken
    assert_same(whole, fast)
    back = read_c3d(p)
    assert back.n_frames == n_frames and back.first_frame == first_frame
    np.testing.assert_array_equal(np.isnan(back.xyz), np.isnan(xyz))


def test_a_last_frame_past_65535_goes_to_ezc3d(tmp_path):
    """Frames 2 to 65,536: the header's last-frame word saturates, so the header does not
    count the frames; ezc3d reads the file as a whole."""
    p = write_c3d(tmp_path / "t.c3d", ["A"], np.ones((65535, 1, 3)), 100.0, first_frame=2)
    layout, fast, whole = both_ways(p)
    assert layout is None
    assert_same(whole, fast)


def test_a_real_residual_goes_to_ezc3d(tmp_path):
    """A residual word other than 0.0 or -1.0 (a real residual, a camera mask) is left to
    ezc3d's decoding: the reader gives ezc3d's answer for the whole file."""
    p = write_c3d(tmp_path / "t.c3d", ["A", "B"], np.ones((50, 2, 3)), 100.0)
    data = bytearray(p.read_bytes())
    ds = (int.from_bytes(data[16:18], "little") - 1) * 512
    data[ds + 12:ds + 16] = np.array([2.5], dtype="<f4").tobytes()   # frame 1, A's word
    p.write_bytes(bytes(data))
    layout, fast, whole = both_ways(p)
    assert layout is not None
    assert_same(whole, fast)


@pytest.mark.realdata
@pytest.mark.slow
def test_real_vicon_files_read_as_before(realdata):
    """The real files (analogs, real residuals, integer or DEC data) are read by ezc3d as
    a whole, as before; the answer is the same either way."""
    files = sorted((realdata / "c3d").glob("*.c3d"))
    assert files
    for p in files:
        try:
            _, fast, whole = both_ways(p)
        except Exception as exc:                        # a file gaitval refuses: both ways
            with pytest.raises(type(exc)):
                _ezc3d_child(p, p, None)
            continue
        assert_same(whole, fast, p.name)
