#!/usr/bin/env python3
"""blueos_labels.py -- an OCI archive of the extension read as BlueOS reads a published image: the config's platform,
then its LABELs as the extensions repository's consolidation parses them (blueos_repository/extension/extension.py:
authors, links, tags, company and permissions by json5, of which JSON is a subset; readme a URL with {tag_name};
type one of ExtensionType; tags kept by validate_filter_tags: at most 10, lower-case, alphanumerics and dashes; the
version a semver tag), and tools/pkg/blueos/metadata.json as the repository's ExtensionMetadata.
Usage: blueos_labels.py ARCHIVE PLATFORM METADATA_JSON (PLATFORM e.g. linux/arm/v7). Prints [  PASS  ]/[  FAIL  ]."""
import json
import re
import sys
import tarfile

ok = True
TYPES = {"device-integration", "example", "theme", "other", "tool"}
SEMVER = re.compile(r"(0|[1-9]\d*)\.(0|[1-9]\d*)\.(0|[1-9]\d*)(?:-[0-9A-Za-z.-]+)?(?:\+[0-9A-Za-z.-]+)?")


def check(cond, what):
    global ok
    print(f"[  {'PASS' if cond else 'FAIL'}  ] {what}", flush=True)
    ok &= bool(cond)
    return cond


def blob(t, digest):
    algo, hexd = digest.split(":", 1)
    return json.load(t.extractfile(f"blobs/{algo}/{hexd}"))


def main():
    archive, platform, meta_path = sys.argv[1:4]
    name = archive.rsplit("/", 1)[-1]
    with tarfile.open(archive) as t:
        index = json.load(t.extractfile("index.json"))
        manifest = blob(t, index["manifests"][0]["digest"])
        config = blob(t, manifest["config"]["digest"])
        layers = sum(l["size"] for l in manifest["layers"])
    plat = "/".join(x for x in (config.get("os"), config.get("architecture"), config.get("variant")) if x)
    check(plat == platform, f"{name}: the image's platform is {plat} (wanted {platform}); {len(manifest['layers'])} layers, "
          f"{layers / 1e6:.1f} MB compressed")
    labels = config.get("config", {}).get("Labels") or {}

    def parsed(key, kind):
        try:
            v = json.loads(labels[key])
        except (KeyError, ValueError) as e:
            check(False, f"{name}: LABEL {key} parses as JSON (json5's strict subset): {e!r}")
            return None
        check(isinstance(v, kind), f"{name}: LABEL {key} is a JSON {kind.__name__}")
        return v if isinstance(v, kind) else None

    check(SEMVER.fullmatch(labels.get("version", "")), f"{name}: LABEL version '{labels.get('version')}' is a semver tag")
    check(labels.get("type") in TYPES, f"{name}: LABEL type '{labels.get('type')}' is one of {sorted(TYPES)}")
    authors = parsed("authors", list) or []
    check(authors and all(isinstance(a, dict) and isinstance(a.get("name"), str) and isinstance(a.get("email"), str)
                          for a in authors), f"{name}: authors are Author(name, email): {authors}")
    company = parsed("company", dict) or {}
    check(isinstance(company.get("name"), str) and set(company) <= {"name", "about", "email"},
          f"{name}: company is Company(name, about, email): {sorted(company)}")
    links = parsed("links", dict) or {}
    check(all(isinstance(links.get(k), str) and links[k].startswith("http") for k in ("website", "support", "docs")),
          f"{name}: links website, support and docs are URLs")
    tags = parsed("tags", list) or []
    kept = [x.lower() for x in tags if isinstance(x, str) and x.replace("-", "").isalnum()][:10]
    check(tags and kept == tags, f"{name}: every tag survives validate_filter_tags unchanged: {tags}")
    readme = labels.get("readme", "")
    check(readme.startswith("http") and "{tag_name}" in readme, f"{name}: readme is a URL with {{tag_name}}: {readme}")
    perm = parsed("permissions", dict) or {}
    host = perm.get("HostConfig", {})
    check(set(perm) <= {"ExposedPorts", "HostConfig", "Env", "Labels", "Cmd", "Entrypoint"} and
          host.get("NetworkMode") == "host" and "8360/tcp" in perm.get("ExposedPorts", {}) and
          any(b.endswith(":/config") for b in host.get("Binds", [])),
          f"{name}: permissions are Docker ContainerCreate fields: host network (the ping service, MAVLink, LCM), "
          f"the view's 8360/tcp, a bind for /config: {json.dumps(perm)}")
    check(config.get("config", {}).get("ExposedPorts", {}).get("8360/tcp") is not None and
          "/config" in (config.get("config", {}).get("Volumes") or {}), f"{name}: the image exposes 8360/tcp and /config")
    meta = json.load(open(meta_path))
    check(all(isinstance(meta.get(k), str) and meta[k] for k in ("name", "website", "docker", "description")) and
          meta["website"] == links.get("website") and re.fullmatch(r"[a-z0-9_.-]+/[a-z0-9_.-]+", meta["docker"]),
          f"metadata.json: name, website (the label's), docker ({meta.get('docker')}) and description")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
