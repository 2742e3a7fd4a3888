#!/usr/bin/python3
"""Peer check of how mfr reads a molecule's atoms: per element and per kind of part, against PyMOL
reading the same file.

* Elements: `mfr info --json` lists molecule.elements (atoms per element, as drawn); PyMOL's
  count of each element must be the same. This covers files without element columns whose atom
  names start in column 13 (AMBER's helix_amber.pdb from PyMOL's tests: gemmi alone reads every
  Cα there as calcium).
* Parts: the atoms of mfr's polymer chains, ligands and water against PyMOL's `polymer`, `organic
  or inorganic` and `solvent` — except the ACE/NME/NH2 caps, which mfr counts with their chain
  (as the wwPDB's mmCIF entities do) and PyMOL as organic.

Files: PyMOL's helix_amber.pdb (no TER, no elements, starts with an acetyl cap), 1hpv, 1tii, il2,
pept, and Biopython's 1A8O (selenomethionine as HETATM inside the chain) and 1LCD (protein and DNA).

usage: pymol_atoms_peer.py MFR_BINARY WORK_DIR
Exit 0 when every file agrees; 1 otherwise (with the differences printed)."""
import gzip
import json
import os
import shutil
import subprocess
import sys

FILES = [
    "/usr/share/pymol/test/dat/helix_amber.pdb",
    "/usr/share/pymol/data/tut/1hpv.pdb",
    "/usr/share/pymol/data/demo/1tii.pdb",
    "/usr/share/pymol/data/demo/il2.pdb",
    "/usr/share/pymol/data/demo/pept.pdb",
    "/usr/share/doc/python-biopython-doc/Tests/PDB/1A8O.pdb.gz",
    "/usr/share/doc/python-biopython-doc/Tests/PDB/1LCD.pdb.gz",
]
CAPS = "resn ACE+NME+NH2"


def pymol_counts(path):
    from pymol import cmd, stored

    cmd.delete("all")
    cmd.load(path, "m")
    # PyMOL reads every model of an ensemble; mfr the first.
    if cmd.count_states("m") > 1:
        cmd.create("model1", "m", 1, 1)
        cmd.delete("m")
        cmd.set_name("model1", "m")
    # mfr keeps the first alternative location of each atom.
    cmd.remove("m and not alt ''+A")
    stored.elements = {}
    cmd.iterate("m", "stored.elements[elem.capitalize()] = stored.elements.get(elem.capitalize(), 0) + 1")
    parts = {
        "polymer": cmd.count_atoms(f"m and (polymer or {CAPS})"),
        "ligands": cmd.count_atoms(f"m and (organic or inorganic) and not {CAPS}"),
        "water": cmd.count_atoms("m and solvent"),
    }
    return stored.elements, parts


def mfr_counts(mfr, work, path):
    out = os.path.join(work, "info.json")
    subprocess.run([mfr, "info", path, "--no-histogram", "--json", out], check=True, stdout=subprocess.DEVNULL)
    with open(out, encoding="utf-8") as f:
        molecule = json.load(f)["molecule"]
    parts = {"polymer": 0, "ligands": 0, "water": 0}
    for name, atoms in molecule["parts"].items():
        parts["ligands" if name == "ligands" else "water" if name == "water" else "polymer"] += atoms
    return molecule["elements"], parts


def main():
    mfr, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failed = False
    for path in FILES:
        if not os.path.exists(path):
            print(f"missing {path} (scripts/setup installs pymol-data and python-biopython-doc)")
            failed = True
            continue
        local = path
        if path.endswith(".gz"):  # PyMOL reads plain files
            local = os.path.join(work, os.path.basename(path)[:-3])
            with gzip.open(path, "rb") as src, open(local, "wb") as dst:
                shutil.copyfileobj(src, dst)
        ours, theirs = mfr_counts(mfr, work, local), pymol_counts(local)
        same = ours == theirs
        print(f"{os.path.basename(path)}: {'same' if same else 'DIFFERENT'}: {sum(ours[0].values())} atoms, "
              f"elements {ours[0]}, parts {ours[1]}")
        if not same:
            failed = True
            print(f"  PyMOL: elements {theirs[0]}, parts {theirs[1]}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
