# What the module promises beyond the command line's files: arrays shared without copies, per-eye decoder state,
# decode_all equal to a loop, the two fixed-point schedules bit-identical (DESIGN §5), the panel and the metrics
# against formulas computed here.
import numpy as np
import pytest

import trm


def srgb(linear):
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1 / 2.4) - 0.055)


@pytest.fixture(scope="module")
def views():
    scene = trm.scene("discs", width=48, height=32)
    encoder = trm.Encoder({"stereo": True})
    return [encoder.encode(scene.frame(t), t, eye) for t in range(4) for eye in range(2)]


def test_arrays_are_shared_and_read_only(views):
    frame = trm.scene("checker", width=20, height=10).frame(0)
    assert frame.shape == (10, 20, 3) and frame.dtype == np.float64
    assert not frame.flags.owndata and not frame.flags.writeable
    codes = views[0].codes
    assert codes.dtype == np.uint16 and not codes.flags.owndata
    assert np.shares_memory(codes, views[0].codes)  # the view's own matrix every time, not a copy


def test_encode_reads_strided_input_like_contiguous():
    frame = trm.scene("zoneplate", width=64, height=32).frame(1)
    encoder = trm.Encoder()
    strided = frame[:, ::2]
    assert not strided.flags.c_contiguous
    np.testing.assert_array_equal(encoder.encode(strided, 0).codes, encoder.encode(np.ascontiguousarray(strided), 0).codes)


def test_full_view_is_the_link_quantisation_of_srgb():
    frame = trm.scene("discs", width=32, height=24).frame(0)
    view = trm.Encoder().encode(frame, 0)
    assert view.parity == "full" and view.codes.shape == (24, 32, 3)
    scaled = srgb(frame) * 255
    near_half = np.abs(scaled - np.floor(scaled) - 0.5) < 1e-9
    expected = np.floor(scaled + 0.5)
    assert np.all((view.codes == expected) | (near_half & (np.abs(view.codes - expected) <= 1)))
    reduced = trm.Encoder().encode(frame, 1)
    assert reduced.parity == "reduced" and reduced.codes.shape == (12, 16, 3)
    assert trm.Encoder().encode(frame, 1, parity="full").codes.shape == (24, 32, 3)


def test_schedules_agree_and_decode_all_equals_a_loop(views):
    streaming, frame_at_a_time, batch = trm.Decoder("fixed"), trm.Decoder("fixed-frame"), trm.Decoder("fixed")
    batched = batch.decode_all(views)
    for view, from_batch in zip(views, batched):
        a, b = streaming.decode(view), frame_at_a_time.decode(view)
        np.testing.assert_array_equal(a.drive_codes, b.drive_codes)
        np.testing.assert_array_equal(a.drive_codes, from_batch.drive_codes)
        np.testing.assert_array_equal(a.emitted_linear, from_batch.emitted_linear)


def test_each_eye_keeps_its_own_state(views):
    together = trm.Decoder("reference")
    interleaved = [together.decode(v) for v in views]
    for eye in (0, 1):
        alone = trm.Decoder("reference")
        for view, out in zip(views, interleaved):
            if view.eye == eye:
                np.testing.assert_array_equal(alone.decode(view).drive_codes, out.drive_codes)


@pytest.mark.parametrize("name", ["reference", "fixed", "fixed-frame"])
def test_without_report_planes_the_codes_are_the_same(views, name):
    with_planes, codes_only = trm.Decoder(name), trm.Decoder(name, report_planes=False)
    for view in views:
        a, b = with_planes.decode(view), codes_only.decode(view)
        assert a.drive is not None and a.wanted_linear is not None and a.emitted_linear is not None
        assert b.drive is None and b.wanted_linear is None and b.emitted_linear is None
        np.testing.assert_array_equal(a.drive_codes, b.drive_codes)
        assert a.stats == b.stats
    assert codes_only.decode_lost(views[0]).drive is None


def test_a_lost_view_holds_the_previous_output(views):
    decoder = trm.Decoder("fixed")
    shown = decoder.decode(views[0])
    lost = decoder.decode_lost(views[2])  # eye 0's next view never arrived
    assert lost.stats["frame_lost"]
    np.testing.assert_array_equal(lost.drive_codes, shown.drive_codes)
    first = trm.Decoder("fixed").decode_lost(views[0])
    assert not first.drive_codes.any()  # nothing shown before: black


def test_outputs_survive_later_decodes(views):
    decoder = trm.Decoder("fixed")
    first = decoder.decode(views[0]).drive_codes
    kept = first.copy()
    for view in views[1:]:
        decoder.decode(view)
    np.testing.assert_array_equal(first, kept)


def test_panel_emission_against_its_formula(views):
    panel = trm.Panel("vive")
    gamma = np.array(panel.config["gamma"])
    drive = np.random.default_rng(5).random((6, 7, 3))
    np.testing.assert_allclose(panel.emitted(drive), drive ** gamma, rtol=1e-14, atol=0)
    decoded = trm.Decoder("fixed").decode(views[0])
    np.testing.assert_allclose(panel.emitted(decoded.drive_codes / 255.0), decoded.emitted_linear, rtol=1e-14, atol=0)
    lcd = trm.Panel("lcd")
    c = lcd.config
    v, p = drive, drive[::-1].copy()
    merged = c["p1"] * (v ** 2 + p ** 2) + c["p2"] * v * p + c["p3"] * (v + p) + c["p4"]
    np.testing.assert_allclose(lcd.emitted(v, p), np.maximum(merged, 0) ** c["gamma"], rtol=1e-12, atol=1e-15)
    assert trm.Panel(lcd.config).config == c


def test_metrics_against_their_formulas():
    rng = np.random.default_rng(7)
    a = rng.random((16, 12, 3))
    b = np.clip(a + rng.normal(0, 0.02, a.shape), 0, 1)
    mse = np.mean((srgb(a) - srgb(b)) ** 2)
    assert trm.psnr_srgb(a, b) == pytest.approx(10 * np.log10(1 / mse), rel=1e-9)
    assert trm.psnr_srgb(a, a) == float("inf")
    assert trm.ssim_srgb(a, a) == pytest.approx(1.0)
    assert trm.ssim_srgb(a, b) < 1.0
    frames = [rng.random((5, 4, 3)) for _ in range(3)]
    expected = np.mean([np.sqrt(((frames[k] - frames[k - 1]) ** 2).sum(axis=2)).mean() for k in (1, 2)])
    assert trm.mtcd(frames) == pytest.approx(expected, rel=1e-12)
    as_codes = [np.round(f * 255).astype(np.uint8) for f in frames]
    assert trm.mtcd(as_codes) == pytest.approx(
        np.mean([np.sqrt(((as_codes[k].astype(float) - as_codes[k - 1]) ** 2).sum(axis=2)).mean() for k in (1, 2)]))
    np.testing.assert_allclose(trm.perceived_pair(a, b), (a + b) / 2, rtol=1e-15)
    line = rng.random((8, 32)) + 0.1
    assert trm.visual_difference_energy(line, line, 11.42, 90.0) == 0.0
    assert trm.visual_difference_energy(line, line * 1.1, 11.42, 90.0) == pytest.approx(
        trm.visual_difference_energy(line * 1.1, line, 11.42, 90.0))


def test_png_round_trip(tmp_path):
    codes = np.random.default_rng(2).integers(0, 1024, (5, 6, 3)).astype(np.uint16)
    trm.write_png(str(tmp_path / "c.png"), codes)
    np.testing.assert_array_equal(trm.read_png(str(tmp_path / "c.png")), codes)


def test_configuration_patches_keep_defaults():
    config = trm.Decoder("fixed", {"sensitivity": 4, "encoder": {"reduction": 0.25}, "panel": "lcd"}).config
    defaults = trm.default_decoder_config()
    assert config["decoder"]["sensitivity"] == 4
    assert config["decoder"]["panel"]["kind"] == "lcd"
    assert config["decoder"]["encoder"]["reduction"] == 0.25
    assert config["decoder"]["encoder"]["sigma"] == pytest.approx(1.25 / 0.25)  # the default sigma follows r
    assert config["formats"] == defaults["formats"]
    assert trm.__version__.count(".") == 2


def test_decoders_run_in_threads(views):
    # The GIL is released while decoding: two decoders in two threads give what they give one after the other.
    from concurrent.futures import ThreadPoolExecutor
    serial = [trm.Decoder("fixed").decode_all(views)[-1].drive_codes for _ in range(2)]
    with ThreadPoolExecutor(2) as pool:
        threaded = list(pool.map(lambda _: trm.Decoder("fixed").decode_all(views)[-1].drive_codes, range(2)))
    for a, b in zip(serial, threaded):
        np.testing.assert_array_equal(a, b)
    shared = trm.Decoder("fixed")  # one decoder shared by threads: serialised, never torn
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda v: shared.decode(v), views))
