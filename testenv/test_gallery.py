"""tools/gallery.py (issue 17, item 4): renders example scenes to a noise target and writes a contact
sheet with their figures and the cloud's light-path split. A smoke test on two scenes with a short
time limit (the full --quick run is timed in the session notes, not here)."""

import json
import os
import subprocess
import sys

from PIL import Image

from conftest import REPO


def test_gallery_writes_a_contact_sheet_with_figures(tmp_path):
    out = tmp_path / "gallery"
    r = subprocess.run([sys.executable, os.path.join(REPO, "tools", "gallery.py"), "--quick", "--out", str(out),
                        "--scenes", "furnace", "vdb_cloud", "--time-limit", "1", "--resolution", "64", "36"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    figures = json.loads((out / "gallery.json").read_text())
    assert [s["scene"] for s in figures["scenes"]] == ["furnace", "vdb_cloud"]
    for s in figures["scenes"]:
        assert s["ok"] and s["stop_reason"] in ("noiseTarget", "timeLimit", "maxSamplesPerPixel")
        assert s["render_seconds"] > 0 and s["mean_samples_per_pixel"] >= 1
    sheet = Image.open(out / "gallery.png")
    # Two scenes and the cloud's three split images: five tiles of 64x36 in rows of three.
    assert sheet.size[0] >= 3 * 64 and sheet.size[1] >= 2 * 36
    assert "contact sheet" in r.stdout
