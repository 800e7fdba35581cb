"""What the Python test scripts share: check() records a failed
expectation and prints it at once ("FAIL: message"); `failures` holds
every one, for the script's own ending (its exit status and summary)."""

failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL:", message, flush=True)
