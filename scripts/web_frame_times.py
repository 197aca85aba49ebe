#!/usr/bin/env python3
"""Frame times of the web page in headless Chromium, for docs/benchmarks.md.

    bash scripts/web.sh --build-only
    python3 scripts/web_frame_times.py [--lights 256,1024,16384,100000] [--size 640x360]
        [--scene sphere-shell] [--pipeline clustered-forward] [--seconds 10]
        [--backend auto|webgpu|webgl2]

Serves target/web on 127.0.0.1, opens each light count in headless Chromium through chromedriver
(started with `--enable-unsafe-webgpu`; frames shown through read-back, on the machine's adapter:
SwiftShader without a GPU), with `backend=` from `--backend` in the page's URL (`auto`, the
default, is WebGPU where Chromium offers it, else WebGL2; `webgl2` forces WebGL2 through ANGLE),
waits for `manylight: ready` and a warm-up, then counts the frames the page rendered in
`--seconds` and prints a Markdown table: milliseconds a frame (wall clock), the median GPU time
the page's stats report (— on WebGL2, which has no timestamp queries), the median CPU time of
the `cluster_assign` pass (WebGL2's CPU-built cluster lists; — where the lists are built on the
GPU), the light count the stats report and the backend they name.
"""

import argparse
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_port(port, what):
    deadline = time.time() + 20
    while time.time() < deadline:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.1)
    sys.exit(f"web_frame_times: {what} did not start on 127.0.0.1:{port}")


def call(method, url, body=None):
    data = json.dumps(body).encode() if body is not None else None
    request = urllib.request.Request(url, data=data, method=method, headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=600) as reply:
        return json.loads(reply.read())


class Page:
    """One headless Chromium session on one page."""

    def __init__(self, driver, url, chromium):
        caps = {"capabilities": {"alwaysMatch": {"browserName": "chrome", "goog:chromeOptions": {
            "binary": chromium,
            "args": ["--headless=new", "--no-sandbox", "--enable-unsafe-webgpu", "--window-size=1400,900"],
        }}}}
        session = call("POST", f"{driver}/session", caps)["value"]["sessionId"]
        self.base = f"{driver}/session/{session}"
        call("POST", f"{self.base}/url", {"url": url})

    def eval(self, script):
        return call("POST", f"{self.base}/execute/sync", {"script": script, "args": []})["value"]

    def close(self):
        call("DELETE", self.base)


def measure(page, seconds):
    start = time.time()
    while page.eval("return document.title") != "manylight: ready":
        error = page.eval("return manylight.error() ?? null")
        if error:
            return {"error": error}
        if time.time() - start > 300:
            return {"error": "not ready within 300 s"}
        time.sleep(0.5)
    ready = time.time() - start
    time.sleep(3)  # warm-up: the first frames size the light lists
    stats = page.eval("return manylight.stats()")
    frames0, t0 = stats["frames_rendered"], time.time()
    gpu, assign = [], []
    while time.time() - t0 < seconds:
        time.sleep(0.5)
        stats = page.eval("return manylight.stats()")
        last = stats["last_frame"]
        if last and last.get("frame_gpu_ms") is not None:
            gpu.append(last["frame_gpu_ms"])
        for p in (last or {}).get("passes", []):
            if p.get("name") == "cluster_assign":
                assign.append(p["cpu_ms"])
    frames = stats["frames_rendered"] - frames0
    elapsed = time.time() - t0
    return {
        "ready_s": ready,
        "frame_ms": elapsed * 1e3 / frames if frames else float("inf"),
        "frames": frames,
        "gpu_ms": statistics.median(gpu) if gpu else None,
        "assign_ms": statistics.median(assign) if assign else None,
        "lights": stats["last_frame"]["light_count"],
        "backend": stats.get("backend"),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lights", default="256,1024,16384,100000")
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--scene", default="sphere-shell")
    parser.add_argument("--pipeline", default="clustered-forward")
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--backend", choices=["auto", "webgpu", "webgl2"], default="auto")
    args = parser.parse_args()
    web = os.path.join(ROOT, "target", "web")
    if not os.path.exists(os.path.join(web, "index.html")):
        sys.exit("web_frame_times: no target/web; run `bash scripts/web.sh --build-only` first")
    chromedriver = os.environ.get("CHROMEDRIVER") or shutil.which("chromedriver")
    chromium = os.environ.get("CHROME_BIN", "/usr/lib/chromium/chromium")
    if not chromedriver:
        sys.exit("web_frame_times: no chromedriver (scripts/setup.sh installs it)")
    page_port, driver_port = free_port(), free_port()
    server = subprocess.Popen(
        [sys.executable, "-m", "http.server", "--bind", "127.0.0.1", "--directory", web, str(page_port)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    driver = subprocess.Popen([chromedriver, f"--port={driver_port}"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        wait_for_port(page_port, "the page server")
        wait_for_port(driver_port, "chromedriver")
        print("| lights | ms a frame | GPU ms (median) | cluster_assign CPU ms (median) | frames "
              "| ready after | backend |")
        print("|---|---|---|---|---|---|---|")
        for lights in [int(n) for n in args.lights.split(",")]:
            query = (f"?scene={args.scene}&lights={lights}&pipeline={args.pipeline}&size={args.size}"
                     f"&overlay=off&present=read-back&backend={args.backend}")
            page = Page(f"http://127.0.0.1:{driver_port}", f"http://127.0.0.1:{page_port}/{query}", chromium)
            try:
                m = measure(page, args.seconds)
            finally:
                page.close()
            if "error" in m:
                print(f"| {lights} | error: {m['error']} | | | | | |")
                continue
            gpu = f"{m['gpu_ms']:.1f}" if m["gpu_ms"] is not None else "—"
            assign = f"{m['assign_ms']:.1f}" if m["assign_ms"] is not None else "—"
            print(f"| {m['lights']} | {m['frame_ms']:.1f} | {gpu} | {assign} | {m['frames']} "
                  f"| {m['ready_s']:.1f} s | {m['backend']} |", flush=True)
    finally:
        driver.kill()
        server.kill()


if __name__ == "__main__":
    main()
