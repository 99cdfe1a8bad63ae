#!/usr/bin/env python3
"""oci_unpack.py -- an OCI archive's file system (its layers in order, whiteouts applied) into DEST, owners kept, as
a container runtime would assemble it; for running an image's programs in a chroot where no runtime runs.
Usage: oci_unpack.py ARCHIVE DEST (as root, to keep owners)."""
import json
import os
import shutil
import sys
import tarfile


def main():
    archive, dest = sys.argv[1:3]
    os.makedirs(dest, exist_ok=True)
    with tarfile.open(archive) as t:
        index = json.load(t.extractfile("index.json"))
        algo, d = index["manifests"][0]["digest"].split(":", 1)
        manifest = json.load(t.extractfile(f"blobs/{algo}/{d}"))
        for layer in manifest["layers"]:
            algo, d = layer["digest"].split(":", 1)
            with tarfile.open(fileobj=t.extractfile(f"blobs/{algo}/{d}"), mode="r:*") as lt:
                keep = []
                for m in lt.getmembers():
                    head, base = os.path.split(m.name)
                    if base == ".wh..wh..opq":  # an opaque directory: what the layers below put there is gone
                        p = os.path.join(dest, head)
                        for e in os.listdir(p) if os.path.isdir(p) else []:
                            q = os.path.join(p, e)
                            shutil.rmtree(q) if os.path.isdir(q) and not os.path.islink(q) else os.unlink(q)
                    elif base.startswith(".wh."):  # a whiteout: the file below is deleted
                        p = os.path.join(dest, head, base[4:])
                        if os.path.isdir(p) and not os.path.islink(p):
                            shutil.rmtree(p)
                        elif os.path.lexists(p):
                            os.unlink(p)
                    elif not m.isdev():
                        keep.append(m)
                lt.extractall(dest, members=keep, numeric_owner=True)


if __name__ == "__main__":
    main()
