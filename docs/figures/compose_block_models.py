"""docs/figures/mineby_block_models.png: the Mine-by tunnel in each block model, one
seed, side by side (docs/field.md, "Rigid against deformable and trigon blocks"):
    bbm sweep examples/field/mineby_in_situ.toml --seeds 6 --threads 2 --out out/mineby_rigid
    bbm sweep examples/field/mineby_in_situ_deformable.toml --seeds 6 --threads 2 --out out/mineby_f05
    bbm sweep examples/field/mineby_in_situ_trigon.toml --seeds 6 --threads 2 --out out/mineby_trigon
    python3 docs/figures/compose_block_models.py docs/figures/mineby_block_models.png 3 \\
        "rigid Voronoi::out/mineby_rigid" "deformable, f = 0.5::out/mineby_f05" "trigon::out/mineby_trigon"
Each panel is the run's failure.png (its legend line cut: one legend below), titled
with its roof and floor notch (the largest lobe within 45 degrees of 104 / 284 degrees)
and whether it came to rest, read from its summary.json."""
import json, sys
from PIL import Image, ImageDraw, ImageFont

out, run = sys.argv[1], int(sys.argv[2])
models = [a.split("::", 1) for a in sys.argv[3:]]
panel_w, top, legend = 520, 62, 40
font = ImageFont.truetype("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", 17)


def near(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def notch(lobes, centre):
    close = [l for l in lobes if near(l["centre_deg"], centre) <= 45]
    return max(close, key=lambda l: l["area_m2"]) if close else None


def subtitle(summary):
    lobes = summary["opening"]["failed_zone"].get("lobes", [])
    text = []
    for name, centre in (("roof", 104), ("floor", 284)):
        l = notch(lobes, centre)
        text.append(f"{name} {l['depth_m']:.2f} m at {l['centre_deg']:.0f}°" if l else f"{name}: none")
    if summary.get("error"):
        state = f"stopped at {summary['steps']:,} steps"
    elif summary["verdict"]["kind"] == "equilibrium":
        state = "in equilibrium"
    else:
        state = f"{summary['verdict']['kind']} at {summary['steps']:,} steps"
    return ", ".join(text) + "; " + state


panels = []
for title, sweep in models:
    folder = f"{sweep}/run_{run:03d}"
    image = Image.open(f"{folder}/failure.png").convert("RGB")
    w, h = image.size
    image = image.crop((0, 0, w, h - 60))
    image = image.resize((panel_w, int(panel_w * image.size[1] / w)), Image.LANCZOS)
    panels.append((title, subtitle(json.load(open(f"{folder}/summary.json"))), image))
panel_h = max(p[2].size[1] for p in panels)
canvas = Image.new("RGB", (panel_w * len(panels) + 10 * (len(panels) - 1), top + panel_h + legend), "white")
draw = ImageDraw.Draw(canvas)
for k, (title, sub, image) in enumerate(panels):
    x = k * (panel_w + 10)
    canvas.paste(image, (x, top))
    draw.text((x + 6, 6), title, fill="black", font=font)
    draw.text((x + 6, 32), sub, fill="black", font=ImageFont.truetype("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", 13))
draw.text((6, top + panel_h + 10),
          f"red: tensile cracks, blue: shear cracks, dashed: failed zone; pattern seeds +{run - 1} (run {run}), "
          "0.12 m blocks; the field's notches: 0.79 m at 104° and 284°",
          fill="black", font=ImageFont.truetype("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", 14))
canvas.quantize(colors=96).save(out, optimize=True)  # a palette: a tenth of the bytes
print(out, canvas.size)
