#!/usr/bin/env python3
"""Headless screenshot (1280x720, lavapipe) of the Rerun viewer's default layout of an .rrd, taken
after the start-up notifications fade, then reduced to 256 colours (octree, no dithering: the
plot colours stay, the file shrinks ~8x). Usage: rerun_screenshot.py FILE.rrd OUT.png PORT
(run with a Python that has rerun-sdk and Pillow; needs Debian's mesa-vulkan-drivers)."""
import subprocess, sys, time, os
from rerun.experimental import ViewerClient
rrd, png, port = sys.argv[1], os.path.abspath(sys.argv[2]), sys.argv[3]
env = dict(os.environ, VK_ICD_FILENAMES="/usr/share/vulkan/icd.d/lvp_icd.x86_64.json")
rerun = os.path.join(os.path.dirname(sys.executable), "rerun")
p = subprocess.Popen([rerun, "--headless", "--renderer", "vulkan", "--window-size", "1280x720",
                      "--bind", "127.0.0.1", "--port", port, rrd], env=env,
                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
try:
    time.sleep(float(os.environ.get("SHOT_WAIT", "20")))
    ViewerClient.connect(f"rerun+http://127.0.0.1:{port}/proxy").save_screenshot(png)
    time.sleep(3)
finally:
    p.terminate(); p.wait()
from PIL import Image
Image.open(png).convert("RGB").quantize(
    colors=256, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE
).save(png, optimize=True)
print(png, os.path.getsize(png))
