#!/usr/bin/env python3
"""Image fidelity of LOD cuts: triangles against PSNR to full detail, for gdr's own DAG and for cut
meshes made by another builder, all rendered by gdr from one camera.

usage: lod_psnr.py --gdr GDR --psnr IMAGE_PSNR --model MODEL --camera px,py,pz,qx,qy,qz,qw --out DIR
                   [--thresholds 0.25,0.5,1,2,4,8] [--reference T=FILE ...] [--targets 47,44.7,40]
                   [--width 1280] [--height 720] [--allow-outside-files]

- full detail: `gdr render MODEL --lod-error 0`;
- gdr's cuts: `gdr render MODEL --lod-error T` for each threshold T (pixels);
- the reference's cuts: `gdr render FILE --lod-error 0` for each --reference T=FILE (drawn as they
  are: the file is already the cut);
every render at WIDTHxHEIGHT from --camera, with --no-cache (a DAG is always the binary's own) and
cluster cone culling and triangle culling off, so that the statistics' `triangles` is the whole cut
(the model in view) rather than its front-facing part; those switches do not change the image.
IMAGE_PSNR (bench/image_psnr) compares each image with full detail: PSNR over the whole image, the
background counted as pixels like any other, and over the pixels the model covers in either image.

Prints a table and, for each target PSNR, the triangles each curve needs to reach it: the fewest
triangles at which the curve (points sorted by triangles, full detail last at infinite PSNR) first
rises to the target, interpolated between the two points around that crossing linearly in PSNR and
logarithmically in triangles; where the crossing is between the last cut and full detail, the
bracket is given instead. Writes DIR/curves.json and the images and statistics of every render.
gdr is run with an argument list (no shell), so file names are passed as they are.
"""
import argparse
import json
import math
import os
import subprocess
import sys


def fail(message, status=1):
    print("lod_psnr: " + message, file=sys.stderr)
    sys.exit(status)


def number_list(text):
    try:
        values = [float(v) for v in text.split(",") if v != ""]
    except ValueError:
        raise argparse.ArgumentTypeError("expected comma-separated numbers: %r" % text)
    if not values or any(not math.isfinite(v) or v < 0 for v in values):
        raise argparse.ArgumentTypeError("expected non-negative numbers: %r" % text)
    return values


def reference(text):
    threshold, sep, path = text.partition("=")
    if not sep or not path:
        raise argparse.ArgumentTypeError("expected T=FILE: %r" % text)
    try:
        return float(threshold), path
    except ValueError:
        raise argparse.ArgumentTypeError("expected a number before '=': %r" % text)


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--gdr", required=True)
    p.add_argument("--psnr", required=True, help="the image_psnr program (bench/image_psnr.c)")
    p.add_argument("--model", required=True)
    p.add_argument("--camera", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--thresholds", type=number_list, default=number_list("0.25,0.5,1,2,4,8"))
    p.add_argument("--reference", type=reference, action="append", default=[])
    p.add_argument("--targets", type=number_list, default=number_list("47,44.7,40"))
    p.add_argument("--width", type=int, default=1280)
    p.add_argument("--height", type=int, default=720)
    p.add_argument("--allow-outside-files", action="store_true")
    return p.parse_args()


def path_arg(path):
    """A file name as a program's argument: one starting with '-' would read as an option."""
    return "./" + path if path.startswith("-") else path


def render(args, scene, lod_error, stem):
    png = os.path.join(args.out, stem + ".png")
    stats = os.path.join(args.out, stem + ".json")
    command = [args.gdr, "render", path_arg(scene), "--width", str(args.width), "--height", str(args.height),
               "--camera", args.camera, "--lod-error", "%g" % lod_error, "--cone-cull", "off",
               "--triangle-cull", "off", "--no-cache", "--out", path_arg(png), "--stats", path_arg(stats)]
    if args.allow_outside_files:
        command.append("--allow-outside-files")
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        fail("%s exited with %d: %s" % (" ".join(command), done.returncode, done.stderr.strip()))
    with open(stats) as f:
        s = json.load(f)
    if s.get("validation_messages", 0):
        fail("%s: %d validation messages" % (stem, s["validation_messages"]))
    return png, s


def psnr(args, full_png, png):
    done = subprocess.run([args.psnr, path_arg(full_png), path_arg(png)], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        fail("image_psnr %s %s: %s" % (full_png, png, done.stderr.strip()))
    r = json.loads(done.stdout)
    for key in ("psnr", "psnr_covered"):
        r[key] = math.inf if r[key] == "inf" else float(r[key])
    return r


def point(args, full_png, scene, lod_error, stem, threshold):
    png, s = render(args, scene, lod_error, stem)
    q = psnr(args, full_png, png)
    return {"threshold": threshold, "triangles": int(s["triangles"]), "psnr": q["psnr"],
            "psnr_covered": q["psnr_covered"], "file": scene}


def triangles_at(points, full_triangles, target):
    """The fewest triangles at which the curve reaches `target` dB, as (value, how)."""
    curve = sorted(((p["triangles"], p["psnr"]) for p in points), key=lambda c: (c[0], -c[1]))
    curve.append((full_triangles, math.inf))  # full detail
    for i, (t, q) in enumerate(curve):
        if q < target:
            continue
        if i == 0:
            return t, "at or below the coarsest cut"
        t0, q0 = curve[i - 1]
        if math.isinf(q):  # full detail, or a cut whose image equals it: no slope to interpolate on
            return t, "between %d (%.2f dB) and %d (%s)" % (t0, q0, t, "full detail" if t == full_triangles
                                                             else "an image equal to full detail")
        f = (target - q0) / (q - q0)
        return math.exp(math.log(t0) + f * (math.log(t) - math.log(t0))), "interpolated"
    return None, "not reached"


def finite(value):
    """JSON has no infinity: an equal image's PSNR is written as the string "inf"."""
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [finite(v) for v in value]
    return value


def fmt_db(q):
    return "inf" if math.isinf(q) else "%.2f" % q


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    full_png, full = render(args, args.model, 0, "full")
    total = int(full["triangles"])
    gdr_points = [point(args, full_png, args.model, t, "gdr_%g" % t, t) for t in args.thresholds]
    ref_points = [point(args, full_png, path, 0, "ref_%g" % t, t) for t, path in args.reference]

    print("model %s, camera %s, %dx%d, full detail %d triangles" % (args.model, args.camera, args.width,
                                                                    args.height, total))
    print("%-10s %10s %12s %10s %14s" % ("builder", "threshold", "triangles", "PSNR dB", "covered dB"))
    for name, points in (("gdr", gdr_points), ("reference", ref_points)):
        for p in sorted(points, key=lambda p: p["triangles"]):
            print("%-10s %10g %12d %10s %14s" % (name, p["threshold"], p["triangles"], fmt_db(p["psnr"]),
                                                 fmt_db(p["psnr_covered"])))
    at = {}
    for target in args.targets:
        row = {}
        for name, points in (("gdr", gdr_points), ("reference", ref_points)):
            if points:
                value, how = triangles_at(points, total, target)
                row[name] = {"triangles": value, "how": how}
        at["%g" % target] = row
        print("at %g dB: %s" % (target, "; ".join(
            "%s %s (%s)" % (n, "-" if r["triangles"] is None else "%.0f" % r["triangles"], r["how"])
            for n, r in row.items())))
    result = {"model": args.model, "camera": args.camera, "width": args.width, "height": args.height,
              "full_triangles": total, "device": full.get("device"), "gdr": gdr_points,
              "reference": ref_points, "triangles_at_psnr": at}
    with open(os.path.join(args.out, "curves.json"), "w") as f:
        json.dump(finite(result), f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
