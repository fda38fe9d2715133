"""pointrast.show(): the browser viewer (`pointrast serve`) on a free localhost port, embedded in Jupyter."""

import json as _json
import os as _os
import secrets as _secrets
import shutil as _shutil
import subprocess as _subprocess
import tempfile as _tempfile
import threading as _threading
import time as _time
import weakref as _weakref
from collections import deque as _deque

# Pages that may frame the viewer: Jupyter (notebook, lab) and VS Code's notebooks on this machine.
_FRAME_ANCESTORS = "'self' http://localhost:* http://127.0.0.1:* https://localhost:* https://127.0.0.1:* vscode-webview:"

# Keyword options of render() that `serve` takes, as its flags.
_FLAGS = dict(method="--method", depth="--depth", color="--color", color_range="--color-range",
              point_size="--point-size", point_shape="--point-shape", point_size_mode="--point-size-mode",
              point_size_max="--point-size-max", dilate="--dilate", edl_strength="--edl-strength",
              edl_radius="--edl-radius", min_node_px="--min-node-px", point_budget="--point-budget",
              gpu_memory="--gpu-memory", background="--background")


def cli_path():
    """The `pointrast` program show() runs: $POINTRAST_CLI, the one installed with the package, the one of
    the build tree the package was built in, or `pointrast` on the PATH."""
    here = _os.path.dirname(_os.path.abspath(__file__))
    candidates = [_os.environ.get("POINTRAST_CLI"), _os.path.join(here, "_bin", "pointrast")]
    try:
        from . import _paths
        candidates.append(_paths.CLI)
    except ImportError:
        pass
    candidates.append(_shutil.which("pointrast"))
    for path in candidates:
        if path and _os.path.isfile(path) and _os.access(path, _os.X_OK):
            return path
    raise RuntimeError("show() runs the pointrast program, which was not found: set POINTRAST_CLI to its path "
                       "or put it on the PATH")


def _text(value):
    if isinstance(value, (tuple, list)):
        return ",".join(_text(v) for v in value)
    if isinstance(value, bool):
        return "1" if value else "0"
    return str(value)


def _serve_flags(options, camera):
    flags = []
    for name, value in options.items():
        if value is None:
            continue
        if name == "edl":
            if value:
                flags.append("--edl")
        elif name in _FLAGS:
            flags += [_FLAGS[name], _text(value)]
        else:
            raise TypeError("show() does not take %s; it takes %s and camera" % (name, ", ".join(["edl"] + list(_FLAGS))))
    if camera is not None:
        for key in ("eye", "target", "up"):
            if camera.get(key) is not None:
                flags += ["--" + key, _text(camera[key])]
        if camera.get("fov") is not None:
            flags += ["--fov", _text(camera["fov"])]
    return flags


def _stop(process, folder):
    """Ends the server (SIGTERM, then SIGKILL after 5 s) and removes the file written for it."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(5)
        except _subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    for stream in (process.stdout, process.stderr):
        if stream:
            stream.close()
    if folder:
        _shutil.rmtree(folder, ignore_errors=True)


class Viewer:
    """A running `pointrast serve` of one scene, on 127.0.0.1 with its own token. In Jupyter it shows as the
    interactive page in a frame; elsewhere open `url` in a browser on this machine. The server stops with
    close(), at the end of a `with` block, or when the object is collected."""

    def __init__(self, process, url, port, folder, height):
        self.url = url
        self.port = port
        self.height = height
        self._process = process
        self._folder = folder  # the temporary file's folder, if show() wrote one
        self._finalizer = _weakref.finalize(self, _stop, process, folder)

    @property
    def pid(self):
        return self._process.pid

    @property
    def running(self):
        return self._process.poll() is None

    def close(self):
        """Stop the server (idempotent)."""
        self._finalizer()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _repr_html_(self):
        if not self.running:
            return "<p>pointrast viewer: stopped</p>"
        return ('<iframe src="%s" width="100%%" height="%d" style="border:0" allow="fullscreen" '
                'title="pointrast viewer"></iframe>' % (self.url, self.height))

    def __repr__(self):
        return "<pointrast.Viewer %s%s>" % (self.url, "" if self.running else " (stopped)")


def show(scene, colors=None, *, camera=None, height=600, timeout=120, device=None, intensity=None,
         classification=None, **options):
    """Show a scene in the interactive browser viewer and return a Viewer (in Jupyter: the page in the
    output cell).

    scene: what render() takes (an (N, 3) array, laspy data, a Cloud, an Octree from open(), or a file or
    octree path). It runs `pointrast serve` on a free port of 127.0.0.1 with a fresh access token; a cloud
    made in Python is handed over as a temporary LAS file, removed when the viewer stops. Options: those of
    render() that the viewer has (method, color, point_size, edl, dilate, min_node_px, gpu_memory, ...);
    camera as render()'s; height: the frame's height in the notebook, pixels. timeout: seconds to wait for
    the server to load the scene.
    """
    from . import _as_cloud, _camera, Cloud, Octree, _core

    folder = None
    if isinstance(scene, (str, _os.PathLike)):
        path = _os.fspath(scene)
        if not _os.path.exists(path):
            raise FileNotFoundError("%s: no such file or folder" % path)
    elif isinstance(scene, Octree):
        path = scene.source
    else:
        cloud = _as_cloud(scene, colors, intensity, classification)
        if (isinstance(scene, Cloud) and cloud.source and _os.path.isfile(cloud.source)):
            path = cloud.source
        else:
            folder = _tempfile.mkdtemp(prefix="pointrast-show-")
            path = _os.path.join(folder, "cloud.las")
            _core.write_las(cloud, path)
    if colors is not None and getattr(colors, "ndim", 0) == 1 and options.get("color") is None:
        options["color"] = "intensity"
    token = _secrets.token_urlsafe(24)
    command = [cli_path(), "serve", path, "--port", "0", "--bind", "127.0.0.1", "--token", token, "--events",
               "--quiet", "--frame-ancestors", _FRAME_ANCESTORS] + _serve_flags(options, _camera(camera))
    if device is not None:
        command += ["--device", str(int(device))]
    try:
        process = _subprocess.Popen(command, stdin=_subprocess.DEVNULL, stdout=_subprocess.PIPE,
                                    stderr=_subprocess.PIPE, text=True)
    except OSError as e:
        if folder:
            _shutil.rmtree(folder, ignore_errors=True)
        raise RuntimeError("could not start %s: %s" % (command[0], e)) from None
    # The server's messages are read as they come (so its pipe never fills); the last ones explain a failure.
    errors = _deque(maxlen=20)
    stderr_reader = _threading.Thread(target=_drain, args=(process.stderr, errors), daemon=True)
    stderr_reader.start()
    listening = _wait_listening(process, timeout)
    if listening is None:
        _stop(process, folder)
        stderr_reader.join(2)
        lines = [l.strip() for l in errors if l.strip()]
        raise ValueError(lines[-1] if lines else "pointrast serve did not start within %g s" % timeout)
    # The events that follow (clients coming and going) are read and dropped.
    _threading.Thread(target=_drain, args=(process.stdout, None), daemon=True).start()
    return Viewer(process, listening["url"], listening["port"], folder, height)


def _wait_listening(process, timeout):
    """The 'listening' event of the server, or None when it exits (or the timeout passes) before it."""
    result = {}

    def read():
        for line in process.stdout:
            try:
                event = _json.loads(line)
            except ValueError:
                continue
            if event.get("event") == "listening":
                result["event"] = event
                return

    reader = _threading.Thread(target=read, daemon=True)
    reader.start()
    deadline = _time.monotonic() + timeout
    while reader.is_alive() and _time.monotonic() < deadline and process.poll() is None:
        reader.join(0.05)
    reader.join(0.5)
    return result.get("event")


def _drain(stream, keep):
    try:
        for line in stream:
            if keep is not None:
                keep.append(line)
    except (ValueError, OSError):
        pass
