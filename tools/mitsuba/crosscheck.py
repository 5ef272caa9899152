#!/usr/bin/env python3
"""Cross-check ref-tracer against Mitsuba 3 (an independent renderer) on a Lambertian built-in scene.

Exports the scene with `cargo xtask scene NAME --obj`, renders it with Mitsuba and with
`cargo xtask render`, and prints RMSE / FLIP (`cargo xtask compare`) of ours against Mitsuba's,
Mitsuba's own noise (the same comparison between two Mitsuba renders of different seeds), the
mean ratio per channel, and Mitsuba's samples per second.

`--integrator direct` (default) compares `env-direct` with Mitsuba's `direct` (one emitter and one
BSDF sample per pixel sample). `--integrator path --max-depth D` compares our `path`, whose D
counts scattering events (D = 1: direct light only), with Mitsuba's `path` at max_depth D + 1:
Mitsuba's depth counts the camera segment too (1 renders only the emitters seen directly).

Run it through `tools/mitsuba/crosscheck.sh`, which makes the Python environment. Not part of CI:
it needs PyPI and a libLLVM >= 17.
"""

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import mitsuba as mi
import numpy as np


def split_obj(obj: Path, out_dir: Path):
    """One OBJ per `o` block (vertex indices renumbered) and each object's Lambertian albedo."""
    v, vn, objects, cur = [], [], [], None
    for line in obj.read_text().splitlines():
        if line.startswith("o "):
            cur = {"name": line[2:].strip(), "faces": [], "albedo": None}
            objects.append(cur)
        elif line.startswith("# material") and cur is not None:
            m = re.match(r"# material lambert albedo ([-\d.e]+) ([-\d.e]+) ([-\d.e]+)$", line)
            if not m:
                sys.exit(f"{obj}: only Lambertian scenes can be cross-checked ({line!r})")
            cur["albedo"] = [float(x) for x in m.groups()]
        elif line.startswith("v "):
            v.append(line)
        elif line.startswith("vn "):
            vn.append(line)
        elif line.startswith("f "):
            cur["faces"].append(line[2:].split())
    shapes = []
    for o in objects:
        vmap, nmap, out_v, out_n, out_f = {}, {}, [], [], []
        for face in o["faces"]:
            corners = []
            for c in face:
                parts = c.split("/")
                vi = int(parts[0])
                if vi not in vmap:
                    vmap[vi] = len(vmap) + 1
                    out_v.append(v[vi - 1])
                s = str(vmap[vi])
                if len(parts) == 3 and parts[2]:
                    ni = int(parts[2])
                    if ni not in nmap:
                        nmap[ni] = len(nmap) + 1
                        out_n.append(vn[ni - 1])
                    s += "//" + str(nmap[ni])
                corners.append(s)
            out_f.append("f " + " ".join(corners))
        path = out_dir / f"{o['name']}.obj"
        path.write_text("\n".join(out_v + out_n + out_f) + "\n")
        shapes.append((o["name"], path, o["albedo"]))
    return shapes


def camera(obj: Path):
    m = re.search(r"# camera eye (\S+) (\S+) (\S+) target (\S+) (\S+) (\S+) up (\S+) (\S+) (\S+) hfov (\S+) deg (\d+) x (\d+)",
                  obj.read_text())
    f = [float(x) for x in m.groups()]
    return f[0:3], f[3:6], f[6:9], f[9], int(f[10]), int(f[11])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="spheres_box")
    ap.add_argument("--envmap", required=True, help=".exr or .hdr map")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--size", default=None, help="WIDTHxHEIGHT (default: the scene's camera)")
    ap.add_argument("--out", default="target/crosscheck")
    ap.add_argument("--integrator", choices=["direct", "path"], default="direct")
    ap.add_argument("--max-depth", type=int, default=3, help="scattering events for --integrator path (ours)")
    args = ap.parse_args()
    if args.max_depth < 1:
        sys.exit("--max-depth must be at least 1")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    obj = out / f"{args.scene}.obj"
    xtask = ["cargo", "xtask"]
    subprocess.run(xtask + ["scene", args.scene, "--obj", str(obj)], check=True)
    eye, target, up, hfov, w, h = camera(obj)
    if args.size:
        w, h = (int(x) for x in args.size.split("x"))
    shapes = split_obj(obj, out)

    mi.set_variant("llvm_ad_rgb")
    scene = {
        "type": "scene",
        "integrator": (
            {"type": "direct", "emitter_samples": 1, "bsdf_samples": 1}
            if args.integrator == "direct"
            # Mitsuba's max_depth counts the camera segment: ours + 1
            else {"type": "path", "max_depth": args.max_depth + 1}
        ),
        "sensor": {
            "type": "perspective", "fov": hfov, "fov_axis": "x",
            "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": args.spp},
        },
        "env": {"type": "envmap", "filename": os.path.abspath(args.envmap)},
    }
    for name, path, albedo in shapes:
        scene[name] = {"type": "obj", "filename": str(path.resolve()),
                       "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}}}
    scene = mi.load_dict(scene)
    mi.render(scene, spp=1)  # compiles the kernels
    start = time.time()
    image = mi.render(scene, spp=args.spp, seed=1)
    image = np.array(image)
    seconds = time.time() - start
    mitsuba_exr = out / "mitsuba.exr"
    mi.Bitmap(image).write(str(mitsuba_exr))
    # a second Mitsuba render, another seed: the noise of one render at this count
    mitsuba2_exr = out / "mitsuba_seed2.exr"
    mi.Bitmap(np.array(mi.render(scene, spp=args.spp, seed=2))).write(str(mitsuba2_exr))

    ours_exr = out / "ours.exr"
    ours_integrator = ["--integrator", "env-direct"] if args.integrator == "direct" else [
        "--integrator", "path", "--max-depth", str(args.max_depth)]
    subprocess.run(xtask + ["render", "--scene", args.scene, "--envmap", args.envmap, "--spp", str(args.spp),
                            "--size", f"{w}x{h}", "--seed", "1", "--out", str(ours_exr)] + ours_integrator,
                   check=True)
    ours = np.array(mi.Bitmap(str(ours_exr)))[:, :, :3]
    ratio = image[:, :, :3].reshape(-1, 3).mean(axis=0) / ours.reshape(-1, 3).mean(axis=0)
    what = "direct" if args.integrator == "direct" else f"path max_depth {args.max_depth + 1} (ours {args.max_depth})"
    print(f"mitsuba 3 {mi.__version__} llvm_ad_rgb, {what}, independent: {w}x{h} {args.spp} spp in {seconds:.2f} s, "
          f"{w * h * args.spp / seconds / 1e6:.2f} M samples/s")
    print(f"mean mitsuba / ours per channel: {ratio[0]:.4f} {ratio[1]:.4f} {ratio[2]:.4f}")
    print("ours against mitsuba (seed 1):", flush=True)
    subprocess.run(xtask + ["compare", str(mitsuba_exr), str(ours_exr)], check=True)
    print("mitsuba's own noise, seed 2 against seed 1:", flush=True)
    subprocess.run(xtask + ["compare", str(mitsuba_exr), str(mitsuba2_exr)], check=True)


if __name__ == "__main__":
    main()
