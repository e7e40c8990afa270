#!/usr/bin/python3
"""What a call through the Python module costs beside the C++ decoder it wraps (README "Python").

Every Decoder.decode(view) is timed from Python (time.perf_counter around the call) and, inside the call, around the
C++ decoder alone (Decoder.last_decode_seconds); their difference is the module's cost for that call: argument
conversion, releasing and taking the GIL, wrapping the result. Paired per call, so the decoder's own variation (a
loaded machine, the first views' allocations) cancels. Also timed: the zero-copy .drive_codes array, and
Decoder.decode_all (the same views in one call) against the Python loop, per view (means, so they include
the machine's stalls). The per-call figures are medians, their mean beside them.

  PYTHONPATH=build/python /usr/bin/python3 tools/python/bench_bindings.py [--size 1080x1200 --size 16x16] [--decoder fixed]
"""
import argparse
import statistics
import time

import trm


def measure(decoder_name, width, height, views_per_run, repeats):
    scene = trm.scene("panorama", width=width, height=height)
    encoder = trm.Encoder()
    views = [encoder.encode(scene.frame(t), t) for t in range(views_per_run)]
    call_overheads, decoder_seconds, access_seconds, loop_runs, batch_runs = [], [], [], [], []
    for repeat in range(repeats):
        decoder = trm.Decoder(decoder_name)
        start_loop = time.perf_counter()
        for view in views:
            start = time.perf_counter()
            out = decoder.decode(view)
            elapsed = time.perf_counter() - start
            call_overheads.append(elapsed - decoder.last_decode_seconds)
            decoder_seconds.append(decoder.last_decode_seconds)
            start = time.perf_counter()
            out.drive_codes
            access_seconds.append(time.perf_counter() - start)
        loop_runs.append(time.perf_counter() - start_loop)
        batch = trm.Decoder(decoder_name)
        start = time.perf_counter()
        batch.decode_all(views)
        batch_runs.append(time.perf_counter() - start)
    overhead = statistics.median(call_overheads)
    overhead_mean = statistics.mean(call_overheads)
    decode = statistics.median(decoder_seconds)
    return {
        "size": f"{width}x{height}", "calls": len(call_overheads), "decode_ms": decode * 1e3,
        "overhead_us": overhead * 1e6, "overhead_mean_us": overhead_mean * 1e6, "overhead_ns_per_line": overhead / height * 1e9,
        "overhead_percent": 100 * overhead / decode, "access_us": statistics.median(access_seconds) * 1e6,
        "loop_ms": statistics.median(loop_runs) / views_per_run * 1e3,
        "batch_ms": statistics.median(batch_runs) / views_per_run * 1e3,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", action="append", help="WxH, repeatable (default 1080x1200 and 16x16)")
    parser.add_argument("--decoder", default="fixed", choices=trm.decoder_names())
    parser.add_argument("--views", type=int, default=6, help="views per repeat at 0.1 Mpix and above (default 6; "
                                                                "smaller views: 500)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"trm {trm.__version__}, decoder {args.decoder}, median over every call of {args.repeats} repeats")
    print(f"{'size':<10} {'calls':>6} {'C++ decode':>12} {'module cost':>12} {'(mean)':>9} {'per line':>10} {'share':>8} "
          f"{'.drive_codes':>13} {'loop/view':>11} {'decode_all/view':>16}")
    for size in args.size or ["1080x1200", "16x16"]:
        width, height = (int(v) for v in size.lower().split("x"))
        views = args.views if width * height >= 100_000 else 500
        r = measure(args.decoder, width, height, views, args.repeats)
        print(f"{r['size']:<10} {r['calls']:>6} {r['decode_ms']:>9.3f} ms {r['overhead_us']:>9.2f} us "
              f"{r['overhead_mean_us']:>6.2f} us "
              f"{r['overhead_ns_per_line']:>7.1f} ns {r['overhead_percent']:>7.3f} % {r['access_us']:>10.2f} us "
              f"{r['loop_ms']:>8.3f} ms {r['batch_ms']:>13.3f} ms")


if __name__ == "__main__":
    main()
