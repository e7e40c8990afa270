# The module under test and the command line it is held to: ctest sets PYTHONPATH to the built module's directory
# and TRM_BINARY to build/trm (tests/python/CMakeLists.txt).
import os
import pathlib

import numpy as np
import pytest


@pytest.fixture(scope="module")
def trm_binary():
    path = os.environ.get("TRM_BINARY")
    if not path or not pathlib.Path(path).is_file():
        pytest.fail("TRM_BINARY must name the built trm command line (ctest sets it)")
    return path


@pytest.fixture
def held_sequence(tmp_path):
    """Writes a held input sequence (frame_000.png, ...) and returns its glob, as `trm decode --input` takes it."""
    import trm

    def write(width, height, frames):
        directory = tmp_path / "input"
        directory.mkdir()
        for t, frame in enumerate(moving_sequence(width, height, frames)):
            trm.write_png(str(directory / f"frame_{t:03d}.png"), frame)
        return str(directory / "frame_*.png")

    return write


def moving_sequence(width, height, frames, seed=3):
    """sRGB 8-bit frames of a textured background with a bright square moving across it: clipping (a residual),
    motion (the motion test) and static regions, independent of trm's own scenes."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width]
    background = np.stack([(x * 255) // max(width - 1, 1), (y * 255) // max(height - 1, 1),
                           np.full_like(x, 96)], axis=-1)
    background = np.clip(background + rng.integers(-12, 13, size=background.shape), 0, 255)
    out = []
    for t in range(frames):
        frame = background.copy()
        left = 3 + 4 * t
        frame[height // 4:height // 4 + height // 3, left:left + width // 4] = 255
        out.append(frame.astype(np.uint8))
    return out
