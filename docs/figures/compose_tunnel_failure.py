"""README's figure, docs/figures/tunnel_failure.png, from the README's first command:
    bbm compare examples/tunnel_voronoi.toml examples/tunnel_voronoi_calibrated.toml \
        examples/tunnel_trigon.toml --out out/tunnel --threads 2
    python3 docs/figures/compose_tunnel_failure.py out/tunnel docs/figures/tunnel_failure.png
The calibrated Voronoi and the trigon tunnel's failure.png side by side, each titled with
its verdict, sector cracks and failed zone read from its summary.json."""
import json, sys
from PIL import Image, ImageDraw, ImageFont

runs, out = sys.argv[1:3]
panels = [("tunnel_voronoi_calibrated", "Voronoi, calibrated joints"), ("tunnel_trigon", "trigon")]
panel_w, panel_h, margin, top = 363, 724, 22, 60
canvas = Image.new("RGB", (2 * panel_w + 3 * margin + 8, top + panel_h + 40), "white")
draw = ImageDraw.Draw(canvas)
font = ImageFont.truetype("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", 13)


def title(summary, name):
    opening = summary["opening"]
    state = "in equilibrium" if summary["verdict"]["kind"] == "equilibrium" else f"still failing at {summary['steps']:,} steps"
    sectors = f"{opening['cracks_springline_sector']} / {opening['cracks_crown_sector']} sector cracks"
    return f"{name}: {state},\n{sectors}, failed zone {opening['failed_zone']['depth_springline']:.2f} m"


for i, (case, name) in enumerate(panels):
    summary = json.load(open(f"{runs}/{case}/summary.json"))
    picture = Image.open(f"{runs}/{case}/failure.png").convert("RGB").resize((panel_w, panel_h), Image.LANCZOS)
    x = margin + i * (panel_w + margin + 8)
    canvas.paste(picture, (x, top))
    draw.multiline_text((x + panel_w / 2, 12), title(summary, name), fill="black", font=font, anchor="ma", align="center")
canvas.save(out)
