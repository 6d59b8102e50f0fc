"""Named checks for the plugin tests: each is printed and all are run, and
finish() exits non-zero when any failed. (The test's own folder is on
sys.path, so a test imports this as plugin_checks.)"""
import sys

failures = []


def check(what, ok):
    print("%s: %s" % ("ok" if ok else "FAILED", what))
    if not ok:
        failures.append(what)


def finish():
    if failures:
        print("%d check(s) failed" % len(failures))
        sys.exit(1)
    print("OK")
