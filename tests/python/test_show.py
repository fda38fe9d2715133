# pointrast.show(): `pointrast serve` on a free localhost port with a fresh token, shown in a frame, stopped
# with the object.
import gc
import json
import os
import pathlib
import shutil
import socket
import subprocess
import time
import urllib.error
import urllib.request

import numpy as np
import pytest

import pointrast

ROOT = pathlib.Path(__file__).resolve().parents[2]


def small_cloud(n=20_000):
    rng = np.random.default_rng(7)
    xyz = rng.random((n, 3)) * [100, 60, 8] + [500_000, 4_000_000, 100]
    colors = rng.integers(0, 256, (n, 3), dtype=np.uint8)
    return xyz, colors


def listening_addresses(port):
    """The local addresses with a TCP socket listening on port (from /proc/net/tcp and tcp6)."""
    found = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(table):
            continue
        with open(table) as f:
            next(f)
            for line in f:
                fields = line.split()
                address, hex_port = fields[1].rsplit(":", 1)
                if int(hex_port, 16) == port and fields[3] == "0A":  # 0A: LISTEN
                    found.append(address)
    return found


def process_gone(pid, seconds=10):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        try:
            with open("/proc/%d/stat" % pid) as f:
                if f.read().split()[2] == "Z":
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


def test_show_serves_on_localhost_only_with_a_token_and_stops_when_collected(cli_path, monkeypatch):
    monkeypatch.setenv("POINTRAST_CLI", str(cli_path))
    xyz, colors = small_cloud()
    viewer = pointrast.show(xyz, colors, point_size=2, edl=True, height=480)
    pid, port, url = viewer.pid, viewer.port, viewer.url
    assert url.startswith("http://127.0.0.1:%d/?token=" % port)
    token = url.split("token=", 1)[1]
    assert len(token) >= 16
    # Listening on the loopback address alone (127.0.0.1, little-endian hex in /proc).
    assert listening_addresses(port) == ["0100007F"]
    with urllib.request.urlopen(url, timeout=10) as page:
        assert page.status == 200
        policy = page.headers["Content-Security-Policy"]
        assert "frame-ancestors 'self' http://localhost:*" in policy
        assert page.headers.get("X-Frame-Options") is None
    # Without the token: refused; the page's script and style alone load without it (a framed page sends
    # no cookie), as they hold no data.
    for path in ("healthz", ""):
        with pytest.raises(urllib.error.HTTPError) as refused:
            urllib.request.urlopen("http://127.0.0.1:%d/%s" % (port, path), timeout=10)
        assert refused.value.code == 403
    with urllib.request.urlopen("http://127.0.0.1:%d/app.js" % port, timeout=10) as script:
        assert script.status == 200
    with urllib.request.urlopen("http://127.0.0.1:%d/healthz?token=%s" % (port, token), timeout=10) as ok:
        assert ok.read() == b"ok\n"
    html = viewer._repr_html_()
    assert '<iframe src="%s"' % url in html and 'height="480"' in html
    # A cloud made in Python went over as a temporary LAS file, removed with the viewer.
    folder = viewer._folder
    assert folder and os.path.isfile(os.path.join(folder, "cloud.las"))

    del viewer
    gc.collect()
    assert process_gone(pid), "the server outlived its Viewer"
    assert not os.path.exists(folder)
    with pytest.raises(OSError):
        socket.create_connection(("127.0.0.1", port), timeout=2).close()


def test_show_of_a_file_and_close(cli_path, monkeypatch, data):
    monkeypatch.setenv("POINTRAST_CLI", str(cli_path))
    with pointrast.show(data / "laz" / "lone-star.copc.laz", height=300) as viewer:
        assert viewer.running
        with urllib.request.urlopen(viewer.url, timeout=10) as page:
            assert page.status == 200
        pid = viewer.pid
    assert not viewer.running and process_gone(pid)
    viewer.close()  # again: nothing happens
    assert "stopped" in repr(viewer) and "stopped" in viewer._repr_html_()


def test_show_reports_the_servers_error(cli_path, monkeypatch, tmp_path):
    monkeypatch.setenv("POINTRAST_CLI", str(cli_path))
    bad = tmp_path / "bad.las"
    bad.write_bytes(b"LASF" + b"\0" * 50)
    with pytest.raises(ValueError, match="bad.las"):
        pointrast.show(bad)
    with pytest.raises(TypeError, match="does not take"):
        pointrast.show(small_cloud(100)[0], no_such_option=1)
    with pytest.raises(FileNotFoundError):
        pointrast.show(tmp_path / "missing.las")


def test_the_viewer_draws_inside_another_origins_frame(cli_path, monkeypatch):
    """The notebook case: the HTML show() gives Jupyter, on a page of another origin, in chromium."""
    node, chromium = shutil.which("node"), os.environ.get("POINTRAST_CHROMIUM", "/usr/bin/chromium")
    if not (node and os.path.exists(chromium) and (ROOT / "tests/web/node_modules/playwright-core").is_dir()):
        if os.environ.get("CI") == "true":
            pytest.fail("node, chromium or playwright-core missing (scripts/web-test-setup.sh installs them)")
        pytest.skip("node, chromium or playwright-core missing (scripts/web-test-setup.sh installs them)")
    monkeypatch.setenv("POINTRAST_CLI", str(cli_path))
    xyz, colors = small_cloud()
    with pointrast.show(xyz, colors, height=400) as viewer:
        run = subprocess.run([node, str(ROOT / "tests/web/embedded.mjs"), viewer._repr_html_()],
                             capture_output=True, text=True, timeout=180, cwd=ROOT / "tests/web")
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["drawn"], result["errors"]
    assert result["frame"]["errors"] == []
    assert result["frame"]["width"] > 0 and result["frame"]["height"] > 0


def test_serve_refuses_frame_ancestors_that_could_end_the_policy(cli_path):
    run = subprocess.run([str(cli_path), "serve", "terrain", "--points", "1000", "--port", "0", "--quiet",
                          "--frame-ancestors", "http://localhost:*; script-src *"],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 1
    assert run.stderr.strip().splitlines()[-1].endswith(
        "--frame-ancestors takes page origins such as http://localhost:* separated by spaces")
