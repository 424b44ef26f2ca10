"""A gym world's rendered frame: gray, resized by averaging bins or repeating pixels (neurocur.contexts.gym_frames)."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.contexts.gym_frames import to_frame


def test_to_frame_averages_bins_and_repeats_pixels():
    rgb = np.zeros((4, 6, 3), dtype=np.uint8)
    rgb[:2, :3] = 255
    np.testing.assert_allclose(to_frame(rgb, (2, 2)), [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(to_frame(rgb, (2, 3)), [1.0, 0.5, 0.0, 0.0, 0.0, 0.0])
    np.testing.assert_allclose(to_frame(rgb[:1, :1], (2, 1)), [1.0, 1.0])
    with pytest.raises(ValueError, match="RGB"):
        to_frame(rgb[:, :, 0], (2, 2))
