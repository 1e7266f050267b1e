"""kernel_packages.py on apt-cache output recorded from Debian's archive."""

import pathlib

import pytest

import kernel_packages

records = pathlib.Path(__file__).parent / "apt-records"


def recorded(name):
    return (records / name).read_text(encoding="utf-8")


def resolve(text, metapackage, suite=None):
    return kernel_packages.resolve(kernel_packages.AptCache(text), metapackage, suite)


def test_a_rebuilt_kbuild_is_taken_at_the_version_the_headers_accept():
    # The headers ask for linux-kbuild-6.1 (>= 6.1.192-2); only 6.1.192-3 and
    # the older 6.1.176-1 are offered.
    assert resolve(recorded("rt-kbuild-rebuilt.txt"), "linux-image-rt-amd64") == [
        ("linux-image-6.1.0-56-rt-amd64", "6.1.192-2"),
        ("linux-headers-6.1.0-56-rt-amd64", "6.1.192-2"),
        ("linux-headers-6.1.0-56-common-rt", "6.1.192-2"),
        ("linux-kbuild-6.1", "6.1.192-3"),
    ]


def test_the_suite_is_taken_over_the_default_candidate():
    # Without the suite apt would install bookworm's 6.1 (priority 500 > 100).
    assert resolve(recorded("backports-6.12.txt"), "linux-image-amd64", "bookworm-backports") == [
        ("linux-image-6.12.95+deb12-amd64", "6.12.95-1~bpo12+1"),
        ("linux-headers-6.12.95+deb12-amd64", "6.12.95-1~bpo12+1"),
        ("linux-headers-6.12.95+deb12-common", "6.12.95-1~bpo12+1"),
        ("linux-kbuild-6.12.95+deb12", "6.12.95-1~bpo12+1"),
    ]


def test_a_new_abi_is_followed_through_the_metapackage():
    assert resolve(recorded("rt-new-abi.txt"), "linux-image-rt-amd64") == [
        ("linux-image-6.1.0-57-rt-amd64", "6.1.195-1"),
        ("linux-headers-6.1.0-57-rt-amd64", "6.1.195-1"),
        ("linux-headers-6.1.0-57-common-rt", "6.1.195-1"),
        ("linux-kbuild-6.1", "6.1.195-1"),
    ]


def test_an_exact_dependency_is_never_moved_to_the_candidate():
    # A rebuilt common-headers package as candidate: the headers still ask
    # for exactly 6.1.192-2, which is still offered.
    text = recorded("rt-kbuild-rebuilt.txt").replace(
        """linux-headers-6.1.0-56-common-rt:
  Installed: (none)
  Candidate: 6.1.192-2
  Version table:
""",
        """linux-headers-6.1.0-56-common-rt:
  Installed: (none)
  Candidate: 6.1.192-3
  Version table:
     6.1.192-3 500
        500 http://deb.debian.org/debian-security bookworm-security/main amd64 Packages
""")
    assert ("linux-headers-6.1.0-56-common-rt", "6.1.192-2") in resolve(text, "linux-image-rt-amd64")


def test_no_version_of_an_unconstrained_package_but_the_candidate():
    # linux-kbuild-6.12.95+deb12 is named without a version: apt installs
    # its candidate, not the newest anything offers.
    text = recorded("backports-6.12.txt").replace(
        """  Candidate: 6.12.95-1~bpo12+1
  Version table:
     6.12.95-1~bpo12+1 100
        100 http://deb.debian.org/debian bookworm-backports/main amd64 Packages
### apt-cache show linux-kbuild-6.12.95+deb12""",
        """  Candidate: 6.12.95-1~bpo12+1
  Version table:
     6.12.95-1~bpo12+2 1
        1 http://deb.debian.org/debian experimental/main amd64 Packages
     6.12.95-1~bpo12+1 100
        100 http://deb.debian.org/debian bookworm-backports/main amd64 Packages
### apt-cache show linux-kbuild-6.12.95+deb12""")
    assert text != recorded("backports-6.12.txt")
    assert resolve(text, "linux-image-amd64", "bookworm-backports")[-1] == (
        "linux-kbuild-6.12.95+deb12", "6.12.95-1~bpo12+1")


def test_an_installed_version_is_offered_too():
    # The host installed linux-kbuild-6.1 6.1.192-3: policy marks it with ***
    # and lists dpkg's status beside the archive.
    text = recorded("rt-kbuild-rebuilt.txt").replace(
        """     6.1.192-3 500
        500 http://deb.debian.org/debian-security bookworm-security/main amd64 Packages
""",
        """ *** 6.1.192-3 500
        500 http://deb.debian.org/debian-security bookworm-security/main amd64 Packages
        100 /var/lib/dpkg/status
""")
    assert text != recorded("rt-kbuild-rebuilt.txt")
    assert resolve(text, "linux-image-rt-amd64")[-1] == ("linux-kbuild-6.1", "6.1.192-3")


def test_a_missing_kbuild_names_the_package_and_the_versions_offered():
    text = recorded("rt-kbuild-rebuilt.txt").replace(
        """     6.1.192-3 500
        500 http://deb.debian.org/debian-security bookworm-security/main amd64 Packages
     6.1.176-1 500""",
        """     6.1.176-1 500""")
    assert text != recorded("rt-kbuild-rebuilt.txt")
    with pytest.raises(kernel_packages.ResolveError) as error:
        resolve(text, "linux-image-rt-amd64")
    message = str(error.value)
    assert "linux-kbuild-6.1 (>= 6.1.192-2)" in message
    assert "offers linux-kbuild-6.1 only at 6.1.176-1" in message
    assert "linux-headers-6.1.0-56-rt-amd64 6.1.192-2 needs" in message


def test_an_unknown_metapackage_says_to_update_apt():
    with pytest.raises(kernel_packages.ResolveError, match="apt knows no linux-image-rt-amd64.*apt-get update"):
        resolve("", "linux-image-rt-amd64")


def test_the_command_prints_package_equals_version(tmp_path, capsys):
    assert kernel_packages.main(["resolve", "linux-image-rt-amd64", "--recorded",
                                 str(records / "rt-kbuild-rebuilt.txt")]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "linux-kbuild-6.1=6.1.192-3"
    empty = tmp_path / "empty.txt"
    empty.write_text("")
    assert kernel_packages.main(["resolve", "linux-image-rt-amd64", "--recorded", str(empty)]) == 1
    assert "kernels: apt knows no linux-image-rt-amd64" in capsys.readouterr().err
