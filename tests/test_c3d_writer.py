"""The C3D writer's fast path (``gaitval.io.c3d_write``): ezc3d writes the header and the
parameters of a one-frame file, numpy the frames; the file must be the one ezc3d writes
alone, byte for byte, whatever the frame count, gaps, events, prefix or first frame."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.c3d import read_c3d


@pytest.mark.parametrize("n_frames, n_markers, first_frame, prefix, with_events", [
    (1, 1, 1, None, False),
    (32, 1, 1, None, True),        # the frames end on a block boundary: a zero block more
    (33, 3, 5, "S1", True),
    (1000, 9, 1, "S1", False),
    (32768, 1, 65000, None, True),  # last frame past 65,535: the header word saturates
    (40000, 3, 1, None, False),     # POINT:FRAMES above 32,767 (an unsigned 16-bit count)
    (65536, 1, 1, "S1", False),     # POINT:FRAMES saturates
    (70000, 9, 1, None, True),      # the ultrasonic trials' size and more
    pytest.param(120000, 9, 1, None, False,   # ROTATION:DATA_START beyond int16: ezc3d
                 marks=pytest.mark.slow),      # writes it all
])
def test_fast_c3d_writer_gives_ezc3ds_bytes(tmp_path, monkeypatch, n_frames, n_markers,
                                             first_frame, prefix, with_events):
    import gaitval.io.c3d_write as W

    rng = np.random.default_rng(n_frames)
    xyz = rng.normal(scale=2.0, size=(n_frames, n_markers, 3))
    xyz[rng.random((n_frames, n_markers)) < 0.02] = np.nan          # gaps
    events = pd.DataFrame({"context": ["Left", "Right"], "label": ["Foot Strike", "Foot Off"],
                           "t_s": [0.5, 1.25]}) if with_events else None
    labels = [f"M{i}" for i in range(n_markers)]
    kw = dict(events=events, first_frame=first_frame, subject_prefix=prefix)
    fast = W.write_c3d(tmp_path / "fast.c3d", labels, xyz, 200.0, **kw).read_bytes()
    monkeypatch.setattr(W, "_FAST", False)
    whole = W.write_c3d(tmp_path / "ezc3d.c3d", labels, xyz, 200.0, **kw).read_bytes()
    assert fast == whole
    assert sorted(f.name for f in tmp_path.iterdir()) == ["ezc3d.c3d", "fast.c3d"]  # no debris
    if n_frames > 0xFFFF:        # ezc3d 1.7.2 would read 65,535 of them: refused, not cut
        with pytest.raises(FileFormatError, match=f"the capture holds {n_frames} frames"):
            read_c3d(tmp_path / "fast.c3d")
        return
    back = read_c3d(tmp_path / "fast.c3d")
    assert back.n_frames == n_frames and back.first_frame == first_frame
    np.testing.assert_allclose(back.xyz, xyz, atol=1e-3)             # float32 of mm
    assert np.array_equal(np.isnan(back.xyz), np.isnan(xyz))
