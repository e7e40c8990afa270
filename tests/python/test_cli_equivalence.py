# A held sequence decoded through Python against `trm decode`'s output files, bit for bit: the drive codes
# (drive8_NNNN.png / drive10_NNNN.png), the 16-bit drive (drive_NNNN.png, round(v 65535) of the unquantised drive)
# and the per-view records of views.jsonl. The Python side builds its encoder and decoder from report.json's
# parameters.decoder, so it also shows that a report's configuration reproduces the run.
import json
import pathlib
import subprocess

import numpy as np
import pytest

import trm

CASES = [
    # impl, extra options, output bits
    ("fixed", ["--panel", "vive"], 8),
    ("fixed-frame", ["--panel", "lcd", "--stereo"], 8),
    ("reference", ["--panel", "rift", "--bits", "10", "--reduction", "0.4"], 10),
    ("fixed", ["--panel", "lcd", "--bits", "10", "--sensitivity", "3"], 10),
]


def run_cli(trm_binary, args):
    result = subprocess.run([trm_binary, *args], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    return result


def drive_16bit(drive):
    # decode's drive_NNNN.png: floor(clamp(v, 0, 1) 65535 + 1/2), the same double operations as the C++ writer
    return np.floor(np.clip(drive, 0.0, 1.0) * 65535.0 + 0.5).astype(np.uint16)


@pytest.mark.parametrize("impl,options,bits", CASES, ids=[f"{c[0]}-{'-'.join(c[1])}" for c in CASES])
def test_python_decode_matches_cli_files(trm_binary, held_sequence, tmp_path, impl, options, bits):
    frames = 5
    pattern = held_sequence(40, 30, frames)
    out = tmp_path / "cli"
    run_cli(trm_binary, ["decode", "--input", pattern, "--out", str(out), "--impl", impl, *options])

    report = json.loads((out / "report.json").read_text())
    config = report["parameters"]["decoder"]
    records = [json.loads(line) for line in (out / "views.jsonl").read_text().splitlines()]
    stereo = "--stereo" in options

    source = trm.image_sequence(pattern)
    assert source.frame_count == frames
    encoder = trm.Encoder(config)
    decoder = trm.Decoder(impl, config)
    # The configuration read back is the one the report wrote.
    if impl == "reference":
        assert decoder.config["decoder"] == config
    else:
        assert decoder.config == config

    compared = 0
    record = iter(records)
    for t in range(frames):
        frame = source.frame(t)
        for eye in range(2 if stereo else 1):
            view = encoder.encode(frame, t, eye)
            decoded = decoder.decode(view)
            suffix = "_right" if eye else ""
            codes = trm.read_png(str(out / f"drive{bits}{suffix}_{t:04d}.png"))
            assert codes.dtype == (np.uint8 if bits == 8 else np.uint16)
            np.testing.assert_array_equal(decoded.drive_codes, codes.astype(np.uint16),
                                          err_msg=f"drive codes of t={t} eye={eye}")
            np.testing.assert_array_equal(drive_16bit(decoded.drive), trm.read_png(str(out / f"drive{suffix}_{t:04d}.png")),
                                          err_msg=f"16-bit drive of t={t} eye={eye}")
            rec = next(record)
            assert (rec["t"], rec["eye"], rec["parity"]) == (t, eye, view.parity)
            assert rec["clipped_fraction"] == decoded.stats["clipped_fraction"]
            assert rec["residual_max_abs"] == decoded.stats["residual_max_abs"]
            if impl != "reference":
                counts = decoder.stage_counts
                events = rec["fixed_point_events"]
                for name in ("beta_clipped", "alpha_clipped", "weight_underflow", "lcd_unreachable"):
                    assert events[name] == counts[name], name
                assert events["skipped"]["motion_test_lines"] == counts["motion_test_lines_skipped"]
            compared += 1
    assert compared == len(records)
    # The sequence exercises what it is meant to: clipping on full frames and a residual used on reduced ones.
    assert any(r["clipped_fraction"] > 0 for r in records if r["parity"] == "full")
    assert any(r.get("residual_applied") for r in records if r["parity"] == "reduced")
