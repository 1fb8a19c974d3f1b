"""Ctrl-C during a render raises KeyboardInterrupt promptly; the GIL is free meanwhile."""
import os
import subprocess
import sys
import textwrap
import threading
import time

import sahara

# A render of minutes, interrupted by SIGINT a moment after it starts.
CHILD = textwrap.dedent("""
    import os, signal, sys, threading, time
    import sahara
    scene = sahara.Scene(None)
    threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    try:
        sahara.render(scene, width=1920, height=1080, spp=100000, threads=1)
    except KeyboardInterrupt:
        print("interrupted after", time.monotonic() - start, flush=True)
        sys.exit(42)
    sys.exit(1)
""")


def test_sigint_stops_a_long_render_with_keyboard_interrupt():
    start = time.monotonic()
    proc = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, timeout=60,
                          env=dict(os.environ))
    elapsed = time.monotonic() - start
    assert proc.returncode == 42, proc.stdout + proc.stderr
    assert "interrupted after" in proc.stdout
    # Import and scene set-up included, far below the render's real length.
    assert elapsed < 20


def test_other_threads_run_while_rendering():
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        sahara.render(None, width=160, height=120, spp=16, threads=1)
    finally:
        done.set()
        t.join()
    assert len(ticks) > 5
