#!/usr/bin/env python3
"""Writes the small seed corpora of the fuzz targets into fuzz/corpus/<target>/ (valid examples
of each format, a few edge cases). The recording seeds come from make_recording_seeds.cpp, the map file seeds from make_map_seeds.cpp.
Run from anywhere: python3 fuzz/make_seed_corpus.py"""
import os
import random
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def put(target, name, data):
    folder = os.path.join(HERE, "corpus", target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


SAMPLES = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}
ADAM7 = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]


def scanlines(rng, w, h, depth, colour, interlace):
    bits = SAMPLES[colour] * depth
    passes = [(w, h)] if not interlace else [
        ((w - x0 + dx - 1) // dx if w > x0 else 0, (h - y0 + dy - 1) // dy if h > y0 else 0)
        for x0, y0, dx, dy in ADAM7]
    out = bytearray()
    for pw, ph in passes:
        if pw == 0 or ph == 0:
            continue
        for _ in range(ph):
            out.append(rng.randrange(5))  # every filter type
            out += bytes(rng.randrange(256) for _ in range((pw * bits + 7) // 8))
    return bytes(out)


def png(rng, w, h, depth, colour, interlace=0, extra=b"", idat_pieces=1):
    ihdr = struct.pack(">IIBBBBB", w, h, depth, colour, 0, 0, interlace)
    data = zlib.compress(scanlines(rng, w, h, depth, colour, interlace), 6)
    step = len(data) // idat_pieces + 1
    idats = b"".join(chunk(b"IDAT", data[i:i + step]) for i in range(0, len(data), step))
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + extra + idats + chunk(b"IEND", b"")


def png_seeds():
    rng = random.Random(13)
    put("png_decoder", "grey8.png", png(rng, 7, 5, 8, 0))
    put("png_decoder", "grey16_depth.png", png(rng, 8, 6, 16, 0, idat_pieces=3))
    put("png_decoder", "bgr8.png", png(rng, 9, 4, 8, 2))
    put("png_decoder", "bgr16.png", png(rng, 3, 3, 16, 2))
    put("png_decoder", "grey_alpha8.png", png(rng, 5, 5, 8, 4))
    put("png_decoder", "bgra8.png", png(rng, 6, 2, 8, 6, extra=chunk(b"tEXt", b"Comment\x00seed")))
    put("png_decoder", "bgra16.png", png(rng, 2, 7, 16, 6))
    palette = chunk(b"PLTE", bytes(rng.randrange(256) for _ in range(3 * 16)))
    put("png_decoder", "palette4_trns.png", png(rng, 11, 3, 4, 3, extra=palette + chunk(b"tRNS", b"\x00\x80")))
    put("png_decoder", "grey1.png", png(rng, 13, 4, 1, 0))
    put("png_decoder", "interlaced_bgr8.png", png(rng, 10, 9, 8, 2, interlace=1))


def text_seeds():
    put("tum_lists", "rgb.txt", "# color images\n# timestamp filename\n"
        "1305031102.175304 rgb/1305031102.175304.png\n1305031102.211214 rgb/1305031102.211214.png\n"
        "1305031102.243211 rgb/1305031102.243211.png\n")
    put("tum_lists", "associations.txt", "1305031102.175304 rgb/1305031102.175304.png "
        "1305031102.160407 depth/1305031102.160407.png\n1305031102.211214 rgb/1305031102.211214.png "
        "1305031102.226738 depth/1305031102.226738.png\n")
    put("tum_lists", "associations_depth_first.txt", "0.000000 depth/0.png 0.000000 rgb/0.png\n"
        "1.000000 depth/1.png 1.000000 rgb/1.png\n")
    put("tum_lists", "commas_tabs_crlf.txt", "1.5,\trgb/a.png\r\n2.5 rgb/b.png  # trailing comment\r\n")
    put("camera_file", "fr1.txt", "# TUM fr1\nfx 517.3\nfy 516.5\ncx 318.6\ncy 255.3\n"
        "k1 0.2624\nk2 -0.9531\np1 -0.0054\np2 0.0026\nk3 1.1633\nwidth 640\nheight 480\n"
        "depth_factor 5000\n")
    put("camera_file", "minimal.txt", "fx 525\nfy 525\ncx 319.5\ncy 239.5\n")
    put("camera_file", "full.txt", "fx 481.2\nfy -480\ncx 319.5\ncy 239.5  # ICL\nwidth 640\nheight 480\n"
        "depth_factor 1000\nbaseline 0.08\nrolling_shutter_readout 0.03\n")
    put("camera_file", "unregistered_depth.txt", "fx 525\nfy 525\ncx 319.5\ncy 239.5\ndepth_factor 1000\n"
        "depth_fx 287.5\ndepth_fy 287.5\ndepth_cx 157\ndepth_cy 121.5\ndepth_k1 -0.05\n"
        "depth_width 320\ndepth_height 240\ndepth_to_colour_qx 0.0015\ndepth_to_colour_qy -0.004\n"
        "depth_to_colour_qz 0.002\ndepth_to_colour_qw 0.99998775\ndepth_to_colour_tx 0.025\n"
        "depth_to_colour_ty 0.001\ndepth_to_colour_tz -0.002\n")
    put("trajectory_reader", "groundtruth.txt", "\x03# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
        "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
        "1305031098.6758 1.3543 0.6306 1.6360 0.6129 0.5966 -0.3316 -0.3980\n")
    put("trajectory_reader", "plumb_lost.txt", "\x01# plumb trajectory\n0.000000 0 0 0 0 0 0 1\n"
        "# 0.033333 lost\n# 0.066667 dropped\n0.100000 0.1 -0.2 0.3 0.01 0.02 0.03 0.9993\n")
    put("trajectory_reader", "commas_duplicate.txt", "\x02" "1.0,0,0,0,0,0,0,1\n1.0\t1\t2\t3\t0\t0\t0\t1\n")
    put("json_reader", "stats.json", '{"frames": 250, "tracked": 249, "ate_rmse_m": 0.0153, '
        '"mode": "fast", "lost": [], "ok": true, "note": null}\n')
    put("json_reader", "trace.json", '{"traceEvents": [{"name": "track", "ph": "X", "ts": 1.5e3, '
        '"dur": 12, "pid": 1, "tid": 2, "args": {"frame": 0}}, {"name": "map\\u00e9\\n", "ph": "i"}]}')
    put("json_reader", "escapes.json", '["\\"\\\\\\/\\b\\f\\n\\r\\t", -0.0, 1E-7, 123456789012345678901234567890, '
        '[[[]]], {"a": {"b": [1, 2, {"c": false}]}}]')


if __name__ == "__main__":
    png_seeds()
    text_seeds()
