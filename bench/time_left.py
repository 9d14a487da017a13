#!/usr/bin/env python3
"""How honest is the progress bar's time left? Runs `snell render ARGS...`
under a pseudo-terminal (the bar shows only on a terminal), notes each
update's percentage and "~T left" with the time it appeared, and compares
T with the time the render really had left (until the bar is erased).

  bench/time_left.py [--all] build/snell render scene.scn -s 1400 -o /tmp/x.png

Prints (--all: every update; else about 40) lines of the updates from 25 % done on (while more than 5 %
of the render is left): done, stated left, true left, error. Exit 0.
"""
import os
import pty
import re
import sys
import time

UPDATE = re.compile(rb"\r?snell: \[[#.]+\]\s+([0-9.]+)%\s+(.*?) elapsed(?:, ~(.*?) left)?")


def seconds(text):
    text = text.decode()
    total = 0.0
    for value, unit in re.findall(r"([0-9.]+) (h|min|s)", text):
        total += float(value) * {"h": 3600, "min": 60, "s": 1}[unit]
    return total


def main():
    argv = sys.argv[1:]
    verbose = bool(argv) and argv[0] == "--all"
    if verbose:
        argv = argv[1:]
    if not argv:
        print(__doc__, file=sys.stderr)
        return 2
    start = time.monotonic()
    pid, fd = pty.fork()
    if pid == 0:
        # The bar goes to stderr: make stdout quiet, stderr the terminal.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.execvp(argv[0], argv)
    samples, buffer, last_update, erased = [], b"", start, None
    while True:
        try:
            chunk = os.read(fd, 4096)
        except OSError:
            break
        if not chunk:
            break
        now = time.monotonic()
        buffer += chunk
        for part in buffer.split(b"\r")[:-1]:
            m = UPDATE.search(b"\r" + part)
            if not m and samples and len(part) > 10 and not part.strip():
                erased = now  # the bar is erased when the render ends
            if m:
                left = seconds(m.group(3)) if m.group(3) else None
                samples.append((now, float(m.group(1)), left))
                last_update = now
        buffer = buffer.split(b"\r")[-1]
    _, status = os.waitpid(pid, 0)
    end = erased if erased is not None else last_update
    render = end - samples[0][0] if samples else 0.0
    print(f"render ~{render:.1f} s after the first update, {len(samples)} updates, status {os.waitstatus_to_exitcode(status)}")
    worst = 0.0
    shown = 0
    for when, done, left in samples:
        true_left = end - when
        if done < 25.0 or left is None or true_left < 0.05 * render:
            continue
        error = (left - true_left) / true_left
        worst = max(worst, abs(error))
        if verbose or shown % max(1, len(samples) // 40) == 0:
            print(f"{done:5.1f} %  stated {left:7.1f} s  true {true_left:7.1f} s  {100 * error:+6.0f} %")
        shown += 1
    print(f"worst error from 25 % on: {100 * worst:.0f} % over {shown} updates")
    return 0


if __name__ == "__main__":
    sys.exit(main())
