# Bad use of the module is a ValueError that says what is wrong, never a crash or a silent conversion.
import numpy as np
import pytest

import trm


@pytest.fixture
def frame():
    return trm.scene("discs", width=24, height=16).frame(0)


@pytest.fixture
def view(frame):
    return trm.Encoder().encode(frame, 0)


def test_wrong_dtype_is_refused_not_converted(frame):
    with pytest.raises(ValueError, match="expected dtype float64, got float32"):
        trm.Encoder().encode(frame.astype(np.float32), 0)
    with pytest.raises(ValueError, match="expected dtype uint16, got int32"):
        trm.View(np.zeros((16, 24, 3), np.int32), 0, "full", 24, 16)
    with pytest.raises(ValueError, match="expected a numpy array"):
        trm.Encoder().encode([[0.5, 0.5, 0.5]], 0)
    with pytest.raises(ValueError, match="line_intact: expected a one-dimensional uint8 array"):
        trm.Decoder("fixed").decode(trm.Encoder().encode(frame, 0), np.ones(16, np.int64))


@pytest.mark.parametrize("shape", [(16, 24), (16, 24, 4), (16, 24, 3, 1), (0, 24, 3)])
def test_wrong_shape(shape):
    with pytest.raises(ValueError, match=r"expected a non-empty array of shape \(height, width, 3\)"):
        trm.Encoder().encode(np.zeros(shape), 0)


def test_out_of_range_values(frame):
    bad = frame.copy()
    bad[3, 4, 1] = np.nan
    with pytest.raises(ValueError, match="NaN, Inf or values outside"):
        trm.Encoder().encode(bad, 0)
    with pytest.raises(ValueError, match="exceeds the 8-bit range"):
        trm.Decoder("fixed").decode(trm.View(np.full((16, 24, 3), 300, np.uint16), 0, "full", 24, 16))
    with pytest.raises(ValueError, match="drive values must lie in"):
        trm.Panel("vive").emitted(frame * 2.0)


def test_unknown_names(view):
    with pytest.raises(ValueError, match="fixed-frame"):  # the message lists the decoders there are
        trm.Decoder("fastest")
    with pytest.raises(ValueError, match="discs"):
        trm.scene("no-such-scene")
    with pytest.raises(ValueError, match="parity must be 'full' or 'reduced'"):
        trm.Encoder().encode(trm.scene("discs", width=8, height=8).frame(0), 0, parity="half")
    with pytest.raises(ValueError, match="parity must be None, 'full' or 'reduced'"):
        trm.Encoder().encode(trm.scene("discs", width=8, height=8).frame(0), 0, parity=3)
    with pytest.raises(ValueError, match="panel"):
        trm.Panel("plasma")


@pytest.mark.parametrize("config,message", [
    ({"sensitivity": -1}, "sensitivity"),
    ({"output_bits": 9}, "output_bits"),
    ({"encoder": {"reduction": 0}}, "reduction"),
    ({"encoder": {"bits": 12}}, "bits"),
    ({"sensitivty": 5}, "unknown field 'sensitivty'"),
    ({"decoder": {}, "formats": {"linear_frac_bits": 3}}, "linear"),
    ({"decoder": {}, "formats": {"no_such_format": 3}}, "unknown field 'no_such_format'"),
    ({"panel": "gamma:9"}, "gamma"),
    ({"panel": {"kind": "oled"}}, "panel"),
    ({"sensitivity": float("nan")}, "not representable as JSON"),
    ({"sensitivity": float("inf")}, "infinite sensitivity is the string"),
    ({"decoder": 5}, "expected an object"),
])
def test_invalid_configuration(config, message):
    with pytest.raises(ValueError, match=message):
        trm.Decoder("fixed", config)


def test_invalid_encoder_configuration():
    with pytest.raises(ValueError, match="sigma"):
        trm.Encoder({"sigma": -2})
    with pytest.raises(ValueError, match="expected a dict"):
        trm.Encoder("r=0.5")


def test_view_that_does_not_match_the_decoder(view):
    with pytest.raises(ValueError, match="link bits 8 but the decoder expects 10"):
        trm.Decoder("fixed", {"encoder": {"bits": 10}}).decode(view)
    with pytest.raises(ValueError, match="must be 12x8"):
        trm.Decoder("reference").decode(trm.View(np.zeros((7, 12, 3), np.uint16), 1, "reduced", 24, 16))
    with pytest.raises(ValueError, match="line mask has 3 entries for a view of 16 lines"):
        trm.Decoder("fixed").decode(view, np.ones(3, np.uint8))
    with pytest.raises(ValueError, match="index"):
        trm.View(np.zeros((16, 24, 3), np.uint16), -1, "full", 24, 16)


def test_metrics_refuse_mismatched_images(frame):
    with pytest.raises(ValueError, match="differ in shape"):
        trm.psnr_srgb(frame, frame[:8])
    with pytest.raises(ValueError, match="frames"):
        trm.mtcd([frame])
    with pytest.raises(ValueError, match=r"shape \(height, width\)"):
        trm.visual_difference_energy(frame, frame, 11.42, 90.0)


def test_files(tmp_path):
    with pytest.raises(ValueError, match="cannot read an image"):
        trm.read_png(str(tmp_path / "missing.png"))
    with pytest.raises(ValueError, match="missing"):
        trm.image_sequence(str(tmp_path / "missing_*.png"))
    with pytest.raises(ValueError, match="cannot write"):
        trm.write_png(str(tmp_path / "no" / "such" / "dir.png"), np.zeros((2, 2, 3), np.uint8))
