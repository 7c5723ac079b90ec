#!/usr/bin/python3
"""Runs the LIGGGHTS side of the side-by-side shear (deck.py) on one thread
and measures its CPU time: the preparation's, read from /proc when the deck
prints PREP_DONE, and the whole process's from wait4; the shear's is their
difference. Then post.py's averages.

usage: run.py RUNDIR [deck.py key=value ...]
Writes RUNDIR/{in.shear, shear.data, params.txt, out.txt, log.lammps,
shear_ave.txt, shear.dump, cpu.txt, result.txt}; result.txt is one line of
key=value pairs (post.py's, then cpu_prep, cpu_shear, cpu_total). With
CDANALYSIS set (a cdanalysis binary) post.py also measures z by it, from
the frames as cdsim snapshots in RUNDIR/snapshots/.
"""
import os
import subprocess
import sys

PY = "/usr/bin/python3"  # Debian's, with python3-numpy
HERE = os.path.dirname(os.path.abspath(__file__))


def cpu_of(pid):
    """User + system CPU seconds of a running process (/proc/PID/stat, fields 14 and 15)."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    rundir = sys.argv[1]
    subprocess.run([PY, os.path.join(HERE, "deck.py"), rundir] + sys.argv[2:], check=True)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    # Line-buffered stdout, so that PREP_DONE arrives when it is printed.
    cmd = ["stdbuf", "-oL", "liggghts", "-in", "in.shear", "-log", "log.lammps"]
    cpu_prep = None
    done = False
    with open(os.path.join(rundir, "out.txt"), "w") as out:
        # errors="replace": LIGGGHTS' error lines can end in stray bytes.
        proc = subprocess.Popen(cmd, cwd=rundir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True, errors="replace")
        for line in proc.stdout:
            out.write(line)
            if cpu_prep is None and line.startswith("PREP_DONE"):
                cpu_prep = cpu_of(proc.pid)
            done = done or line.startswith("SHEAR_DONE")
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0 or cpu_prep is None or not done:
        sys.exit("run.py: liggghts failed (exit %d%s); see %s/out.txt" %
                 (proc.returncode, "" if done else ", no SHEAR_DONE line", rundir))
    cpu_total = usage.ru_utime + usage.ru_stime
    cda = ["cda=" + os.environ["CDANALYSIS"]] if os.environ.get("CDANALYSIS") else []
    post = subprocess.run([PY, os.path.join(HERE, "post.py"), rundir] + cda, check=True, text=True,
                          stdout=subprocess.PIPE).stdout.strip()
    line = "%s cpu_prep=%.2f cpu_shear=%.2f cpu_total=%.2f" % (post, cpu_prep, cpu_total - cpu_prep, cpu_total)
    with open(os.path.join(rundir, "result.txt"), "w") as f:
        f.write(line + "\n")
    print(line)


if __name__ == "__main__":
    main()
