"""Checks files against the CF conventions with two checkers and prints every problem: the CF
Checker `cfchecks` (cfchecker, with UDUNITS) and the IOOS `compliance-checker` (the CF-1.11
rules). Exit status 1 if either reports any error or warning.

    .venv/bin/python scripts/cf_check.py atlas/out/demo.h5 atlas/out/paper-c-diagram.h5

Notes. cfchecks wants a `.nc` name, so each file is checked through a symbolic link with
that suffix. The files say "CF-1.11" (the first CF version with the unsigned bytes of the
flags); cfchecker 4.1 knows versions up to 1.8 only, so it is taught the name "CF-1.11" and
applies every rule it has (those of 1.0 to 1.8), while compliance-checker checks by 1.11. The CF
tables cfchecks reads come without a network: the standard name table that
compliance-checker ships, and stand-in area-type and region tables (the files use neither).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import subprocess
import sys
import tempfile
from pathlib import Path

AREA_TYPES = """<?xml version="1.0"?>
<area_type_table><version_number>stand-in</version_number><date>2026-11-23</date><entry id="land"/></area_type_table>
"""
REGIONS = """<?xml version="1.0"?>
<standard_region_list><version_number>stand-in</version_number><date>2026-11-23</date><entry id="global"/></standard_region_list>
"""


def cfchecks(path: Path, folder: Path) -> list[str]:
    """The errors and warnings cfchecks reports for `path` (checked as a .nc link in `folder`)."""
    import compliance_checker
    from cfchecker import cfchecks as cf

    cf_1_11 = cf.CFVersion((1, 11))
    if cf_1_11 not in cf.cfVersions:
        cf.cfVersions.append(cf_1_11)
    names = Path(compliance_checker.__file__).parent / "data" / "cf-standard-name-table.xml"
    (folder / "area-types.xml").write_text(AREA_TYPES)
    (folder / "regions.xml").write_text(REGIONS)
    link = folder / (path.stem + ".nc")
    if link.exists() or link.is_symlink():
        link.unlink()
    link.symlink_to(path.resolve())
    checker = cf.CFChecker(cfStandardNamesXML=str(names), cfAreaTypesXML=str(folder / "area-types.xml"),
                           cfRegionNamesXML=str(folder / "regions.xml"), version=cf_1_11, silent=False)
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        try:
            checker.checker(str(link))
        except cf.FatalCheckerError:
            pass
    totals = checker.get_total_counts()
    problems = [line.strip() for line in printed.getvalue().splitlines()
                if line.startswith(("ERROR:", "WARN:", "FATAL:"))]
    if (totals["FATAL"] + totals["ERROR"] + totals["WARN"]) and not problems:
        problems.append(f"cfchecks: {totals}")
    return [f"cfchecks: {p}" for p in problems]


def compliance(path: Path, folder: Path) -> list[str]:
    """The problems compliance-checker reports for `path` by the CF-1.11 rules."""
    link = folder / (path.stem + ".nc")
    out = subprocess.run([sys.executable, "-c",
                          "import sys; from compliance_checker.runner import ComplianceChecker, CheckSuite; "
                          "CheckSuite.load_all_available_checkers(); "
                          "ok, errors = ComplianceChecker.run_checker(sys.argv[1], ['cf:1.11'], 0, 'normal', "
                          "output_filename='-', output_format='text'); sys.exit(0 if ok and not errors else 1)",
                          str(link)], capture_output=True, text=True)
    if "All tests passed!" in out.stdout and out.returncode == 0:
        return []
    lines = [line.strip() for line in out.stdout.splitlines() if line.strip().startswith("*")]
    return [f"compliance-checker: {line}" for line in lines] or [f"compliance-checker: {out.stdout[-2000:]}{out.stderr[-2000:]}"]


def problems_in(path: Path) -> list[str]:
    """Every problem either checker finds in the file at `path`, checked in this process."""
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        return cfchecks(path, folder) + compliance(path, folder)


def check(path: str | Path) -> list[str]:
    """Every problem either checker finds in the file at `path` (empty: it passes both). The
    checkers load netCDF4, which brings an HDF5 library of its own: they run in a process of
    their own, never beside h5py in the caller's."""
    out = subprocess.run([sys.executable, __file__, str(path)], capture_output=True, text=True)
    problems = [line.strip() for line in out.stdout.splitlines() if line.startswith("  ")]
    if out.returncode not in (0, 1) or (out.returncode == 1 and not problems):
        problems.append(f"cf_check.py failed: {out.stderr[-2000:]}")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("files", nargs="+", help="HDF5/netCDF files written by rubber-atlas or the package")
    args = parser.parse_args(argv)
    failed = 0
    for f in args.files:
        problems = problems_in(Path(f))
        print(f"{f}: {'passes both checkers' if not problems else f'{len(problems)} problem(s)'}")
        for p in problems:
            print(f"  {p}")
        failed += bool(problems)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
