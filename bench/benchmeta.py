"""Machine and commit description recorded beside every benchmark table."""
import os
import platform
import subprocess
import time


def machine_info():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "-C", root, "describe", "--always"],
                                capture_output=True, text=True, check=True).stdout.strip()
        # Dirty only if the measured code differs from the commit (the results and the doc
        # this run rewrites do not count).
        changed = subprocess.run(["git", "-C", root, "diff", "--quiet", "HEAD", "--", "src",
                                  "CMakeLists.txt", "bench/*.cpp", "bench/*.hpp", "cases"])
        if changed.returncode != 0:
            commit += "-dirty"
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    return {"cpu": cpu, "cores": os.cpu_count(), "kernel": platform.release(),
            "commit": commit, "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
            "load_1min_at_end": round(load, 2)}
