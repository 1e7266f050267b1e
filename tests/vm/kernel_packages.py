#!/usr/bin/env python3
"""Which Debian packages make up a kernel of the VM suite: its image and the
headers that build modules for it, each at the version apt would install.

A kernel's packages are not all rebuilt together: the archive may carry a
rebuild of linux-kbuild-6.1 (6.1.192-3) beside an image and headers of
6.1.192-2, whose headers ask for `linux-kbuild-6.1 (>= 6.1.192-2)`.  So each
package is resolved from the dependency that names it, never pinned to the
image's version.

usage: kernel_packages.py resolve METAPACKAGE [--suite SUITE] [--recorded FILE]
  prints PACKAGE=VERSION per line, the image first; exits 1 naming the
  package and the versions the archive offers when a kernel cannot be had.
  --suite     take the metapackage from SUITE (bookworm-backports), not the
              version apt would install by default
  --recorded  read `apt-cache policy` and `apt-cache show` output recorded in
              FILE (sections headed `### apt-cache policy|show PACKAGE`)
              instead of asking apt
"""

import argparse
import functools
import re
import subprocess
import sys

# The header packages' dependencies that building a module needs: the
# flavour-independent headers and the kbuild tools.  Compilers and
# linux-base come from the host.
NEEDED_BY_HEADERS = re.compile(r"^linux-(headers-.*-common.*|kbuild-.*)$")


class ResolveError(Exception):
    pass


class AptCache:
    """apt-cache's answers, live or as recorded."""

    def __init__(self, recorded=None):
        self.recorded = None
        if recorded is not None:
            self.recorded = {}
            section = None
            for line in recorded.splitlines():
                header = re.match(r"^### apt-cache (policy|show) (\S+)$", line)
                if header:
                    section = self.recorded.setdefault(header.groups(), [])
                elif section is not None:
                    section.append(line)

    def _output(self, command, package):
        if self.recorded is not None:
            return "\n".join(self.recorded.get((command, package), []))
        result = subprocess.run(["apt-cache", command, package], capture_output=True, text=True)
        return result.stdout if result.returncode == 0 else ""

    def versions(self, package):
        """(candidate, {version: [suite, ...]}) from apt-cache policy."""
        candidate = None
        table = {}
        current = None
        for line in self._output("policy", package).splitlines():
            found = re.match(r"^\s+Candidate:\s+(\S+)", line)
            if found:
                candidate = None if found.group(1) == "(none)" else found.group(1)
                continue
            # "     6.1.192-2 500", or " *** 6.1.192-3 500" when installed
            found = re.match(r"^\s+(?:\*\*\*\s+)?(\S+)\s+-?\d+$", line)
            if found:
                current = table.setdefault(found.group(1), [])
                continue
            found = re.match(r"^\s+-?\d+\s+\S+\s+(\S+?)/\S+\s", line)
            if found and current is not None:
                current.append(found.group(1))
        return candidate, table

    def depends(self, package, version):
        """The Depends field of PACKAGE at VERSION, parsed (see parse_depends)."""
        record = {}
        # Records end at a blank line, or where the next one begins.
        for line in self._output("show", package).splitlines() + [""]:
            if not line.strip() or line.startswith("Package:"):
                if record.get("Version") == version:
                    return parse_depends(record.get("Depends", ""))
                record = {}
                if not line.strip():
                    continue
            key, _, value = line.partition(":")
            if not line.startswith(" "):
                record[key] = value.strip()
        raise ResolveError(f"apt-cache show has no record of {package} {version}")


def parse_depends(field):
    """'a (>= 1), b | c' -> [[('a', '>=', '1')], [('b', None, None), ('c', None, None)]]"""
    groups = []
    for group in field.split(","):
        alternatives = []
        for alternative in group.split("|"):
            found = re.match(r"^\s*([^\s(:]+)(?::\S+)?\s*(?:\(\s*(<<|<=|=|>=|>>)\s*([^)\s]+)\s*\))?", alternative)
            if found and found.group(1):
                alternatives.append(found.groups())
        if alternatives:
            groups.append(alternatives)
    return groups


def compare_versions(a, b):
    if a == b:
        return 0
    less = subprocess.run(["dpkg", "--compare-versions", a, "lt", b]).returncode == 0
    return -1 if less else 1


def satisfies(version, relation, wanted):
    if relation is None:
        return True
    order = compare_versions(version, wanted)
    return {"<<": order < 0, "<=": order <= 0, "=": order == 0, ">=": order >= 0, ">>": order > 0}[relation]


def describe(package, relation, wanted):
    return f"{package} ({relation} {wanted})" if relation else package


def choose(apt, package, relation, wanted, suite, asked_by):
    """The version of PACKAGE apt would take for the dependency: the suite's
    (or by default the candidate) when it satisfies the relation, otherwise
    the newest offered version that does."""
    candidate, table = apt.versions(package)
    if not table:
        raise ResolveError(f"{asked_by} needs {describe(package, relation, wanted)}, "
                           f"and apt knows no {package} (run apt-get update)")
    by_age = sorted(table, key=functools.cmp_to_key(compare_versions), reverse=True)
    fitting = [version for version in by_age if satisfies(version, relation, wanted)]
    if not fitting:
        raise ResolveError(f"{asked_by} needs {describe(package, relation, wanted)}, "
                           f"and the archive offers {package} only at {', '.join(by_age)}")
    if suite:
        in_suite = [version for version in fitting if suite in table[version]]
        if in_suite:
            return in_suite[0]
    elif candidate in fitting:
        return candidate
    return fitting[0]


def resolve(apt, metapackage, suite=None):
    """[(package, version)]: the image first, then its headers and what they need."""
    candidate, table = apt.versions(metapackage)
    if suite:
        offered = sorted((v for v, suites in table.items() if suite in suites),
                         key=functools.cmp_to_key(compare_versions), reverse=True)
        meta_version = offered[0] if offered else None
    else:
        meta_version = candidate
    if meta_version is None:
        raise ResolveError(f"apt knows no {metapackage}{' in ' + suite if suite else ''} "
                           "(run apt-get update)")
    image_dependency = apt.depends(metapackage, meta_version)
    if not image_dependency:
        raise ResolveError(f"{metapackage} {meta_version} depends on no kernel image")
    image, relation, wanted = image_dependency[0][0]
    image_version = choose(apt, image, relation, wanted, suite, f"{metapackage} {meta_version}")
    resolved = [(image, image_version)]

    headers = image.replace("linux-image-", "linux-headers-", 1)
    # The headers must be those of this very build of the image.
    headers_version = choose(apt, headers, "=", image_version, suite, f"{image} {image_version}")
    resolved.append((headers, headers_version))
    for group in apt.depends(headers, headers_version):
        package, relation, wanted = group[0]
        if NEEDED_BY_HEADERS.match(package):
            resolved.append((package, choose(apt, package, relation, wanted, suite,
                                             f"{headers} {headers_version}")))
    return resolved


def main(argv):
    parser = argparse.ArgumentParser(prog="kernel_packages.py")
    commands = parser.add_subparsers(dest="command", required=True)
    command = commands.add_parser("resolve")
    command.add_argument("metapackage")
    command.add_argument("--suite")
    command.add_argument("--recorded")
    arguments = parser.parse_args(argv)
    recorded = None
    if arguments.recorded:
        with open(arguments.recorded, encoding="utf-8") as file:
            recorded = file.read()
    try:
        for package, version in resolve(AptCache(recorded), arguments.metapackage, arguments.suite):
            print(f"{package}={version}")
    except ResolveError as error:
        print(f"kernels: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
