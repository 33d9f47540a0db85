"""Streams a G-code file to taut through grbl-streamer (PyPI), the real
client, as its README shows: connect (it sends Ctrl-X and waits for the
`Grbl ` banner, then asks `$$`, `$#`, `$G`), poll `?`, stream in
character-counting mode (`incremental_streaming = False`), wait for the
job to complete and the machine to stand. Prints what it saw; exits 1 on
any error or alarm, or a timeout.

The job is started on grbl-streamer's own reader thread. Its `job_run()`
fills the receive buffer on the caller's thread while the reader thread
sends the next line on every `ok`, with no lock between the two: when an
`ok` came back before the first fill ended (a loaded host, a fast
controller), a line went out twice and the next one never (seen: `G21`
twice, line 8 of the walk skipped; the firmware ran exactly what it got).
Started from the `ok` of a harmless `G4 P0`, every fill runs on one thread.

usage: grbl_streamer_client.py PORT FILE TIMEOUT_S
"""
import sys
import threading
import time

from grbl_streamer import GrblStreamer

port, path, timeout = sys.argv[1], sys.argv[2], float(sys.argv[3])
booted = threading.Event()
completed = threading.Event()
start_on_ok = threading.Event()
errors, alarms, states = [], [], []


def on_event(event, *data):
    if event == "on_boot":
        booted.set()
    elif event == "on_error":
        errors.append(data)
    elif event == "on_alarm":
        alarms.append(data)
    elif event == "on_job_completed":
        completed.set()
    elif event == "on_rx_buffer_percent" and start_on_ok.is_set():
        # The end of its `ok` handling, on the reader thread.
        start_on_ok.clear()
        grbl.job_run()
    elif event == "on_stateupdate":
        if not states or states[-1] != data[0]:
            states.append(data[0])


def finish(code, why):
    print(f"grbl-streamer: {why}; states {states}; errors {errors}; alarms {alarms}", flush=True)
    grbl.poll_stop()
    time.sleep(0.5)  # its polling thread ends before the port closes
    grbl.disconnect()
    sys.exit(code)


grbl = GrblStreamer(on_event)
grbl.cnect(port, 115200)
if not booted.wait(10):
    finish(1, "no banner")
grbl.poll_interval = 0.2
grbl.poll_start()
time.sleep(1.0)  # its $$, $# and $G answered
grbl.incremental_streaming = False
grbl.load_file(path)
start = time.time()
completed.clear()  # it reports a completed job at boot
start_on_ok.set()
grbl.send_immediately("G4 P0")
if not completed.wait(timeout):
    finish(1, "the job did not complete")
# Every line answered; then the machine runs the last moves and stands.
while not ("Run" in states and states[-1] == "Idle") and time.time() - start < timeout:
    time.sleep(0.1)
if errors or alarms or states[-1:] != ["Idle"]:
    finish(1, f"ended {grbl.cmode}")
finish(0, f"streamed {grbl.buffer_size} lines in {time.time() - start:.1f} s")
