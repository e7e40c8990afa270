#!/usr/bin/python3
"""What calling the decoder from Python costs: a Python loop of Decoder.decode() against Decoder.decode_all(), the same
C++ decoder over the same views in one call, at the sizes given (README "Python"). Each repeat builds fresh decoders
outside the timing and alternates the order; figures are medians over repeats.

  PYTHONPATH=build/python /usr/bin/python3 tools/python/bench_bindings.py [--size 1080x1200 --size 64x48] [--views 8]
"""
import argparse
import statistics
import time

import trm


def timed(function):
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def measure(decoder_name, width, height, views_per_run, repeats):
    scene = trm.scene("panorama", width=width, height=height)
    encoder = trm.Encoder()
    views = [encoder.encode(scene.frame(t), t) for t in range(views_per_run)]
    loop_times, batch_times, access_times = [], [], []
    for repeat in range(repeats):
        loop_decoder, batch_decoder = trm.Decoder(decoder_name), trm.Decoder(decoder_name)
        outputs = []

        def python_loop():
            for view in views:
                outputs.append(loop_decoder.decode(view))

        def in_one_call():
            batch_decoder.decode_all(views)

        runs = [(python_loop, loop_times), (in_one_call, batch_times)]
        for function, times in runs if repeat % 2 == 0 else reversed(runs):
            times.append(timed(function))
        access_times.append(timed(lambda: [o.drive_codes for o in outputs]) / len(outputs))
    loop = statistics.median(loop_times) / views_per_run
    batch = statistics.median(batch_times) / views_per_run
    overhead = loop - batch
    return {
        "size": f"{width}x{height}", "decoder": decoder_name, "per_view_ms_python": loop * 1e3,
        "per_view_ms_cpp": batch * 1e3, "overhead_us_per_call": overhead * 1e6,
        "overhead_ns_per_line": overhead / height * 1e9, "overhead_percent": 100 * overhead / batch,
        "array_access_us": statistics.median(access_times) * 1e6,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", action="append", help="WxH (repeatable); default 1080x1200 and 64x48")
    parser.add_argument("--decoder", default="fixed", choices=trm.decoder_names())
    parser.add_argument("--views", type=int, default=8, help="views per run (default 8)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    sizes = args.size or ["1080x1200", "64x48"]
    print(f"trm {trm.__version__}, decoder {args.decoder}, {args.views} views per run, median of {args.repeats}")
    print("size        per view (Python loop)   per view (decode_all)   overhead per call   per line   share   "
          ".drive_codes")
    for size in sizes:
        width, height = (int(v) for v in size.lower().split("x"))
        # small views run in microseconds: more of them per run for a stable figure
        views = args.views if width * height >= 100_000 else args.views * 50
        r = measure(args.decoder, width, height, views, args.repeats)
        print(f"{r['size']:<11} {r['per_view_ms_python']:>14.3f} ms {r['per_view_ms_cpp']:>20.3f} ms "
              f"{r['overhead_us_per_call']:>15.2f} us {r['overhead_ns_per_line']:>8.1f} ns "
              f"{r['overhead_percent']:>6.2f} % {r['array_access_us']:>8.2f} us")


if __name__ == "__main__":
    main()
