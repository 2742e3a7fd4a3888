#!/usr/bin/python3
"""Peer check of the secondary structure a cartoon draws (`--molecule cartoon`), for files that
record it (PDB HELIX/SHEET): PyMOL reads the same records, and its `ss` of every polymer Cα
(H helix, S strand, L or blank loop) must equal, chain by chain and residue by residue, the
letters `mfr info --json` lists (molecule.secondary_structure.chains: H, E, -). Files: PyMOL's
tutorial HIV protease (1hpv: two chains, sheets) and its five-chain demo (1tii).

For a file without records PyMOL runs its own `dss`, which is not DSSP; there mfr is checked
against mkdssp instead (tests/data/test_molecule_cartoon.cpp). To show the comparison can fail,
the same letters are compared with PyMOL's `dss` of 1hpv (its own assignment, not the file's
records): they must differ somewhere.

usage: pymol_secondary_structure_peer.py MFR_BINARY WORK_DIR
Exit 0 when every chain agrees and the dss control differs; 1 otherwise (with the chains printed)."""
import json
import os
import subprocess
import sys

FILES = ["/usr/share/pymol/data/tut/1hpv.pdb", "/usr/share/pymol/data/demo/1tii.pdb"]


def pymol_letters(path, run_dss=False):
    from pymol import cmd, stored

    cmd.delete("all")
    cmd.load(path, "m")
    if run_dss:
        cmd.dss("m")
    stored.rows = []
    cmd.iterate("polymer and name CA", "stored.rows.append((chain, ss))")
    chains = {}
    for chain, ss in stored.rows:
        name = "chain " + chain if chain.strip() else "chain (blank)"
        chains[name] = chains.get(name, "") + {"H": "H", "S": "E"}.get(ss, "-")
    return chains


def mfr_letters(mfr, work, path):
    out = os.path.join(work, "info.json")
    subprocess.run([mfr, "info", path, "--no-histogram", "--json", out], check=True, stdout=subprocess.DEVNULL)
    with open(out, encoding="utf-8") as f:
        ss = json.load(f)["molecule"]["secondary_structure"]
    if ss["source"] != "file":
        sys.exit(f"{path}: mfr did not take the file's records (source {ss['source']})")
    return ss["chains"]


def main():
    mfr, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failed = False
    for path in FILES:
        ours, theirs = mfr_letters(mfr, work, path), pymol_letters(path)
        residues = sum(len(s) for s in ours.values())
        print(f"{os.path.basename(path)}: chains {sorted(ours)} / PyMOL {sorted(theirs)}, {residues} residues")
        if ours != theirs:
            failed = True
            for chain in sorted(set(ours) | set(theirs)):
                print(f"  {chain}\n    mfr:   {ours.get(chain)}\n    PyMOL: {theirs.get(chain)}")
    control = pymol_letters(FILES[0], run_dss=True)
    if control == mfr_letters(mfr, work, FILES[0]):
        print("control: PyMOL's own dss of 1hpv equals the file's records; the comparison could not tell them apart")
        failed = True
    else:
        print("control: PyMOL's own dss of 1hpv differs from the records, as expected")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
