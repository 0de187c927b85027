"""A single-node SLURM cluster on localhost, for testing the cohort workflow
on a real scheduler (test_workflow_slurm.py) and for trying it by hand:

    python3 scripts/workflow/local_slurm.py DIR   # starts it, prints SLURM_CONF, Ctrl-C stops it

munged, slurmctld and slurmd (Debian's munge and slurm-wlm) run in the
foreground as children of this process, with their key, configuration,
state, sockets and logs in one directory, on free ports: nothing in /etc is
used, several clusters can run side by side, and the daemons die with the
process that started them (PR_SET_PDEATHSIG), even when it is killed.
slurmd tracks processes through /proc and binds no tasks
(proctrack/linuxproc, task/none), so it needs no cgroups: it runs as root
in a container as well as on a workstation.
"""
import contextlib
import ctypes
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

PROGRAMS = ("munged", "mungekey", "slurmctld", "slurmd", "sbatch", "sinfo", "scancel")
NODE = "fibletnode"


def missing_programs():
    return [p for p in PROGRAMS if shutil.which(p) is None and not Path("/usr/sbin", p).exists()]


def _program(name):
    return shutil.which(name) or str(Path("/usr/sbin", name))


def _die_with_parent():
    # Linux: the kernel sends SIGKILL to the daemon when its parent dies.
    PR_SET_PDEATHSIG = 1
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def _free_ports(n):
    socks = [socket.socket() for _ in range(n)]
    for s in socks:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in socks]
    for s in socks:
        s.close()
    return ports


def _node_hardware():
    """CPUs and RealMemory (MB) as slurmd measures them (`slurmd -C`)."""
    out = subprocess.run([_program("slurmd"), "-C"], capture_output=True, text=True, timeout=30).stdout
    cpus = int(re.search(r"\bCPUs=(\d+)", out).group(1))
    memory = int(re.search(r"\bRealMemory=(\d+)", out).group(1))
    return cpus, memory


def slurm_conf(d, ports, cpus, memory):
    host = socket.gethostname()
    return f"""# Single-node SLURM for fiblet's workflow test (scripts/workflow/local_slurm.py).
ClusterName=fiblet
SlurmctldHost={host}(127.0.0.1)
SlurmUser={_user()}
SlurmdUser={_user()}
SlurmctldPort={ports[0]}
SlurmdPort={ports[1]}
AuthType=auth/munge
AuthInfo=socket={d}/munge.sock
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/slurmctld.log
SlurmdLogFile={d}/slurmd.log
# No cgroups: processes tracked through /proc, tasks not bound to CPUs.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
# At least 2 CPUs (the compress rule asks for 2 threads), even on a 1-CPU machine.
SlurmdParameters=config_overrides
NodeName={NODE} NodeHostname={host} NodeAddr=127.0.0.1 CPUs={max(cpus, 2)} RealMemory={memory} State=UNKNOWN
PartitionName=fiblet Nodes=ALL Default=YES MaxTime=INFINITE State=UP
"""


def _user():
    import pwd
    return pwd.getpwuid(os.getuid()).pw_name


class LocalSlurm:
    """Context manager: `with LocalSlurm(dir) as env:` runs the cluster;
    `env` is os.environ plus SLURM_CONF, for sbatch and friends."""

    def __init__(self, directory, start_timeout=60):
        self.dir = Path(directory).resolve()
        self.start_timeout = start_timeout
        self.procs = []
        self.env = dict(os.environ)

    def log_tail(self, lines=20):
        out = []
        for name in ("munged.out", "slurmctld.out", "slurmd.out"):
            p = self.dir / name
            if p.exists():
                out.append(f"== {p}\n" + "\n".join(p.read_text(errors="replace").splitlines()[-lines:]))
        return "\n".join(out)

    def _start(self, name, args):
        log = open(self.dir / f"{name}.out", "w")
        self.procs.append(subprocess.Popen([_program(name), *args], stdout=log, stderr=subprocess.STDOUT,
                                           stdin=subprocess.DEVNULL, env=self.env, preexec_fn=_die_with_parent))
        log.close()

    def _wait_for(self, what, ready):
        deadline = time.monotonic() + self.start_timeout
        while time.monotonic() < deadline:
            for p in self.procs:
                if p.poll() is not None:
                    raise RuntimeError(f"{p.args[0]} exited with {p.returncode} while waiting for {what}\n"
                                       + self.log_tail())
            if ready():
                return
            time.sleep(0.5)
        raise TimeoutError(f"{what} not ready after {self.start_timeout} s\n" + self.log_tail())

    def _node_idle(self):
        r = subprocess.run([_program("sinfo"), "-h", "-n", NODE, "-o", "%t"], env=self.env, capture_output=True,
                           text=True, timeout=10)
        return r.returncode == 0 and r.stdout.strip() == "idle"

    def __enter__(self):
        d = self.dir
        if len(str(d / "munge.sock")) > 100:  # sun_path holds 108 bytes
            raise ValueError(f"{d}: too long a path for the munge socket")
        for sub in ("state", "spool"):
            (d / sub).mkdir(parents=True, exist_ok=True)
        subprocess.run([_program("mungekey"), "--create", "--force", f"--keyfile={d}/munge.key"], check=True,
                       timeout=30)
        os.chmod(d / "munge.key", 0o600)
        conf = d / "slurm.conf"
        conf.write_text(slurm_conf(d, _free_ports(2), *_node_hardware()))
        self.env["SLURM_CONF"] = str(conf)
        try:
            self._start("munged", ["--foreground", "--force", f"--key-file={d}/munge.key",
                                   f"--socket={d}/munge.sock", f"--pid-file={d}/munged.pid",
                                   f"--log-file={d}/munged.log", f"--seed-file={d}/munged.seed"])
            self._wait_for("munged", lambda: (d / "munge.sock").exists())
            self._start("slurmctld", ["-D", "-f", str(conf)])
            self._start("slurmd", ["-D", "-N", NODE, "-f", str(conf)])
            self._wait_for(f"node {NODE} idle", self._node_idle)
        except BaseException:
            self.stop()
            raise
        return self.env

    def __exit__(self, *exc):
        self.stop()

    def stop(self):
        """Cancels what is left, stops the daemons (SIGTERM, then SIGKILL)."""
        if self.procs:
            with contextlib.suppress(Exception):
                subprocess.run([_program("scancel"), "--full", "--partition=fiblet"], env=self.env,
                               capture_output=True, timeout=10)
        for p in reversed(self.procs):  # slurmd, slurmctld, then munged
            if p.poll() is None:
                p.terminate()
        for p in self.procs:
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=15)
        self.procs = []


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    with LocalSlurm(sys.argv[1]) as env:
        print(f"export SLURM_CONF={env['SLURM_CONF']}   # Ctrl-C stops the cluster", flush=True)
        with contextlib.suppress(KeyboardInterrupt):
            signal.pause()
