"""`tesseral view` in a real browser: headless Chromium with software GL (SwiftShader).

Run by scripts/view-browser-test, which installs what it needs. Each check prints
one line; the run ends with "N passed, N failed". With --figures it also measures
the showcase page (size, load time, frame time at 1024x1024).

Checks:
- first_frame_matches_render: the page's first picture against `tesseral render`
  from the same camera (the four named views, and perspective) (--no-shadows --normals faces): silhouette IoU >= 0.97, and
  the colours of pixels both cover within a tolerance;
- drag_turns_the_view: a scripted mouse drag changes the camera and the picture;
- cut_removes_what_it_should: with the cut plane z < C, every voxel under the
  cursor has z < C, the kept-voxel count is exact, and pixels that showed voxels
  above the plane no longer do;
- info_panel_counts: the panel's voxel count is the CLI's;
- slice_and_outlines_draw: slice mode and outlines draw something;
- time_slider_plays_frames: an `rsmc --view` page moves to its last frame by its
  slider, and the grown surface covers more of the picture;
- page_is_self_contained: no http(s) URL in the page.
"""

import base64
import io
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from PIL import Image
from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BIN = os.path.join(ROOT, "target", "release", "tesseral")
BACKGROUND = np.array([250, 250, 252])

# A box of 40 x 30 x 20 voxels (24,000) and a ball: known counts and two colours.
BOX_SCENE = """depth 6
bounds [0, 0, 0] [64, 64, 64]
box(size = [40, 30, 20]) at [30, 31, 14] colour "steel"
sphere(r = 9) at [30, 31, 33] colour "red"
"""


def tesseral(*args):
    out = subprocess.run([BIN, *args], check=True, capture_output=True, text=True)
    return out.stdout


def browser(user_dir):
    opts = Options()
    opts.binary_location = "/usr/bin/chromium"
    for flag in [
        "--headless=new",
        "--no-sandbox",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        "--disable-dev-shm-usage",
        "--window-size=1200,1200",
        "--user-data-dir=" + user_dir,
    ]:
        opts.add_argument(flag)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)


def open_page(driver, path, width, height):
    driver.get("file://" + path)
    for _ in range(600):
        ready = driver.execute_script("return window.tesseral && window.tesseral.ready")
        if ready is not None:
            break
        time.sleep(0.05)
    if not ready:
        logs = [e["message"] for e in driver.get_log("browser")]
        err = driver.execute_script("return window.tesseral && window.tesseral.error")
        raise RuntimeError(f"page not ready: {err} {logs}")
    driver.execute_script("document.getElementById('panel').classList.add('hidden')")
    driver.execute_script(f"tesseral.setSize({width}, {height})")


def snapshot(driver):
    url = driver.execute_script("return tesseral.snapshot()")
    data = base64.b64decode(url.split(",", 1)[1])
    return np.array(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)


def mask(img):
    return np.any(img != BACKGROUND, axis=2)


def iou(a, b):
    return (a & b).sum() / max((a | b).sum(), 1)


RESULTS = []


def check(name):
    def wrap(f):
        def run(*args):
            try:
                detail = f(*args)
                RESULTS.append(True)
                print(f"ok   {name}: {detail}", flush=True)
            except Exception as e:  # a failed check is reported, the others still run
                RESULTS.append(False)
                print(f"FAIL {name}: {e}", flush=True)

        return run

    return wrap


@check("first_frame_matches_render")
def first_frame_matches_render(driver, work, scene, view, size, perspective=False):
    w, h = size
    ref = os.path.join(work, f"ref-{view}.png")
    extra = ["--perspective"] if perspective else []
    tesseral("render", scene, "-o", ref, "--size", f"{w}x{h}", "--view", view,
             "--no-shadows", "--normals", "faces", *extra)
    cpu = np.array(Image.open(ref).convert("RGB")).astype(int)
    page = os.path.join(work, "first.html")
    tesseral("view", scene, "-o", page)
    open_page(driver, page, w, h)
    driver.execute_script(f"tesseral.setView('{view}')")
    if perspective:
        driver.execute_script("tesseral.set({perspective: true})")
    gpu = snapshot(driver)
    assert gpu.shape == cpu.shape, f"{gpu.shape} vs {cpu.shape}"
    Image.fromarray(gpu.astype(np.uint8)).save(os.path.join(work, f"page-{view}.png"))
    a, b = mask(cpu), mask(gpu)
    assert a.mean() > 0.05, f"the CPU picture is nearly empty ({a.mean():.3f})"
    score = iou(a, b)
    assert score >= 0.97, f"IoU {score:.4f} < 0.97"
    both = a & b
    diff = np.abs(cpu[both] - gpu[both]).max(axis=1)
    close = (diff <= 12).mean()
    assert close >= 0.95, f"only {close:.3f} of pixels within 12 levels"
    view += " perspective" if perspective else ""
    return f"{scene} {view}: IoU {score:.4f}, {close:.3f} of pixels within 12 levels, median {np.median(diff)}"


@check("drag_turns_the_view")
def drag_turns_the_view(driver, work, scene):
    page = os.path.join(work, "drag.html")
    tesseral("view", scene, "-o", page)
    open_page(driver, page, 480, 360)
    before = snapshot(driver)
    az0 = driver.execute_script("return tesseral.state.azimuth")
    canvas = driver.find_element(By.ID, "view")
    ActionChains(driver).move_to_element_with_offset(canvas, -200, 0).click_and_hold() \
        .move_by_offset(60, 0).move_by_offset(60, 20).release().perform()
    after = snapshot(driver)
    az1 = driver.execute_script("return tesseral.state.azimuth")
    changed = np.any(before != after, axis=2).mean()
    assert az1 != az0, "the azimuth did not change"
    assert changed > 0.02, f"only {changed:.4f} of pixels changed"
    return f"azimuth {az0:.1f} -> {az1:.1f}, {changed:.3f} of pixels changed"


@check("cut_removes_what_it_should")
def cut_removes_what_it_should(driver, work, box_scene):
    page = os.path.join(work, "cut.html")
    tesseral("view", box_scene, "-o", page)
    open_page(driver, page, 320, 240)
    w, h = 320, 240
    grid = [(x, y) for x in range(4, w, 8) for y in range(4, h, 8)]
    picks = driver.execute_script(
        "return arguments[0].map(p => tesseral.pick(p[0], p[1]))", grid)
    high = sum(1 for p in picks if p and p["abs"][2] >= 14)
    # The box spans z 4..24 and the ball z 24..42: cut at z < 14 through the
    # panel's own controls.
    driver.execute_script("document.getElementById('panel').classList.remove('hidden')")
    driver.find_element(By.ID, "cut").click()
    driver.execute_script(
        "const s = document.getElementById('cut-at'); s.value = 14;"
        "s.dispatchEvent(new Event('input'))")
    state = driver.execute_script("return [tesseral.state.cut, tesseral.state.cutAt]")
    assert state == [True, 14], state
    picks = driver.execute_script(
        "return arguments[0].map(p => tesseral.pick(p[0], p[1]))", grid)
    above = [p["abs"] for p in picks if p and p["abs"][2] >= 14]
    assert not above, f"voxels above the plane still shown: {above[:3]}"
    assert high > 50, f"the test needs pixels above the plane first ({high})"
    kept = driver.execute_script("return tesseral.kept()")
    assert kept == 40 * 30 * 10, f"kept {kept}, expected 12000"
    time.sleep(0.3)
    text = driver.find_element(By.ID, "info").text
    assert "12,000 voxels" in text, text
    img = snapshot(driver)
    # Cut faces are drawn darker than the box's own top.
    assert mask(img).mean() > 0.05
    return f"{high} grid pixels above z=14 before, none after; kept 12,000 voxels"


@check("info_panel_counts")
def info_panel_counts(driver, work, scene):
    page = os.path.join(work, "info.html")
    tesseral("view", scene, "-o", page)
    open_page(driver, page, 320, 240)
    driver.execute_script("document.getElementById('panel').classList.remove('hidden')")
    want = json.loads(tesseral("render", scene, "-o", os.path.join(work, "x.png"),
                               "--size", "64x48", "--json"))["voxels"]
    text = driver.find_element(By.ID, "info").text
    line = next(l for l in text.splitlines() if l.startswith("voxels"))
    got = int(line.split()[1].replace(",", ""))
    assert got == want, f"panel says {got}, render --json {want}"
    return f"{got:,} voxels"


@check("slice_and_outlines_draw")
def slice_and_outlines_draw(driver, work, scene):
    page = os.path.join(work, "slice.html")
    tesseral("view", scene, "-o", page)
    open_page(driver, page, 320, 240)
    plain = snapshot(driver)
    driver.execute_script("tesseral.set({outline: true})")
    outlined = snapshot(driver)
    assert np.any(plain != outlined), "outlines changed nothing"
    driver.execute_script("tesseral.set({outline: false, slice: true, sliceAxis: 2})")
    sliced = snapshot(driver)
    assert mask(sliced).mean() > 0.01, "the slice is empty"
    assert np.any(sliced != plain)
    return f"slice covers {mask(sliced).mean():.3f} of the picture"


@check("time_slider_plays_frames")
def time_slider_plays_frames(driver, work):
    page = os.path.join(work, "rsmc.html")
    tesseral("rsmc", "--steps", "4000", "--sample-every", "1000", "-o",
             os.path.join(work, "rsmc-run"), "--no-picture", "--view", page)
    open_page(driver, page, 320, 240)
    first = snapshot(driver)
    driver.execute_script("document.getElementById('panel').classList.remove('hidden')")
    driver.execute_script(
        "const s = document.getElementById('time'); s.value = s.max;"
        "s.dispatchEvent(new Event('input'))")
    last = snapshot(driver)
    label = driver.find_element(By.ID, "time-label").text
    frames = driver.execute_script("return tesseral.state.frame + 1")
    assert frames == 5, f"on frame {frames} of 5"
    assert label.startswith("step 4000"), label
    assert mask(last).sum() > mask(first).sum(), "the grown surface covers no more"
    return f"{label}: {mask(first).sum()} -> {mask(last).sum()} pixels"


@check("page_is_self_contained")
def page_is_self_contained(work):
    page = os.path.join(work, "first.html")
    text = open(page, encoding="utf-8").read()
    assert "http://" not in text and "https://" not in text
    return f"{len(text):,} bytes, no URL"


def figures(driver, work):
    scene = os.path.join(ROOT, "scenes", "showcase.tss")
    page = os.path.join(work, "showcase.html")
    start = time.time()
    out = json.loads(tesseral("view", scene, "-o", page, "--json"))
    print(f"showcase: page {out['page_bytes']:,} bytes, depth {out['shown_depth']} of {out['depth']}, "
          f"{out['leaves']:,} leaves, {out['entries']:,} entries, written in {time.time() - start:.1f} s")
    start = time.time()
    driver.get("file://" + page)
    while not driver.execute_script("return window.tesseral && window.tesseral.ready"):
        time.sleep(0.02)
    load = time.time() - start
    in_page = driver.execute_script("return tesseral.loadMs")
    print(f"showcase: load {load:.2f} s (script done {in_page:.0f} ms after navigation start)")
    driver.execute_script("document.getElementById('panel').classList.add('hidden'); tesseral.setSize(1024, 1024)")
    driver.set_script_timeout(600)
    for view in ["iso", "top"]:
        driver.execute_script(f"tesseral.setView('{view}')")
        ms = driver.execute_script("return tesseral.bench(3)")
        print(f"showcase: frame time at 1024x1024, {view}, SwiftShader: {ms:.0f} ms")
    driver.execute_script("tesseral.setView('iso')")
    Image.fromarray(snapshot(driver).astype(np.uint8)).save(os.path.join(work, "showcase.png"))


def screenshot(driver, work, path):
    """The README's picture: the showcase page with its panel, a cut through the dome."""
    scene = os.path.join(ROOT, "scenes", "showcase.tss")
    page = os.path.join(work, "showcase.html")
    tesseral("view", scene, "-o", page)
    driver.set_window_size(960, 640)
    driver.set_script_timeout(600)
    driver.get("file://" + page)
    while not driver.execute_script("return window.tesseral && window.tesseral.ready"):
        time.sleep(0.05)
    driver.execute_script("tesseral.set({cut: true, cutAxis: 1, cutAt: 512}); tesseral.draw()")
    time.sleep(1.0)
    driver.save_screenshot(path)
    print(f"wrote {path}")


def main():
    if not os.path.exists(BIN):
        subprocess.run(["cargo", "build", "--release", "-p", "tesseral-cli"], check=True, cwd=ROOT)
    keep = os.environ.get("VIEW_TEST_OUT")
    with tempfile.TemporaryDirectory() as tmp:
        work = keep or tmp
        os.makedirs(work, exist_ok=True)
        box_scene = os.path.join(work, "box.tss")
        with open(box_scene, "w") as f:
            f.write(BOX_SCENE)
        tank = os.path.join(ROOT, "scenes", "tank.tss")
        driver = browser(os.path.join(tmp, "profile"))
        try:
            if "--screenshot" in sys.argv:
                screenshot(driver, work, os.path.abspath(sys.argv[sys.argv.index("--screenshot") + 1]))
                return
            if "--figures-only" in sys.argv:
                figures(driver, work)
                return
            for view in ["iso", "front", "top", "side"]:
                first_frame_matches_render(driver, work, tank, view, (640, 480))
            first_frame_matches_render(driver, work, box_scene, "iso", (400, 400))
            first_frame_matches_render(driver, work, tank, "iso", (480, 360), True)
            drag_turns_the_view(driver, work, tank)
            cut_removes_what_it_should(driver, work, box_scene)
            info_panel_counts(driver, work, tank)
            slice_and_outlines_draw(driver, work, tank)
            time_slider_plays_frames(driver, work)
            page_is_self_contained(work)
            if "--figures" in sys.argv:
                figures(driver, work)
        finally:
            driver.quit()
    passed, failed = RESULTS.count(True), RESULTS.count(False)
    print(f"{passed} passed, {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
