#!/usr/bin/python3
"""Writes DIR/MANIFEST.tsv for scripts/fetch-data.sh.

    /usr/bin/python3 scripts/data/manifest.py DIR SOURCES.tsv RECIPE

SOURCES.tsv: one line per file, `path under DIR, package, version, path in the
package, derivation`. The manifest adds each file's size and SHA-256, and
every file under DIR must have exactly one line.
"""
import hashlib
import os
import sys

out, sources, recipe = sys.argv[1:]
rows = {}
with open(sources) as f:
    for line in f:
        path, *rest = line.rstrip("\n").split("\t")
        if path in rows:
            sys.exit("fetch-data: internal: %s listed twice" % path)
        rows[path] = rest
found = set()
for root, _, files in os.walk(out):
    found.update(os.path.relpath(os.path.join(root, n), out) for n in files)
found.discard("MANIFEST.tsv")
if found != set(rows):
    sys.exit("fetch-data: internal: files without a source: %s; sources without a file: %s"
             % (sorted(found - set(rows)) or "none", sorted(set(rows) - found) or "none"))
lines = ["# recipe " + recipe,
         "# path\tbytes\tsha256\tpackage\tversion\tpath in the package\tderivation"]
for path in sorted(rows):
    with open(os.path.join(out, path), "rb") as f:
        data = f.read()
    lines.append("\t".join([path, str(len(data)), hashlib.sha256(data).hexdigest()] + rows[path]))
with open(os.path.join(out, "MANIFEST.tsv.part"), "w") as f:
    f.write("\n".join(lines) + "\n")
os.replace(os.path.join(out, "MANIFEST.tsv.part"), os.path.join(out, "MANIFEST.tsv"))
