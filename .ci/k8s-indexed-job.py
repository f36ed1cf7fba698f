"""CI: runs the container command of examples/batch/k8s-indexed-job.yaml as the Job's pods
would, once per completion index (JOB_COMPLETION_INDEX), here instead of on a cluster: the
shard mapping of the recipe runs for real. Checks the Job's shape first (an Indexed Job whose
SHARDS is its completion count); runs it with SHARDS and the completions set to SHARDS_HERE,
and SCENE and OUT pointing here.

Usage: k8s-indexed-job.py JOB.yaml HALO4D SCENE OUT SHARDS_HERE
"""

import os
import subprocess
import sys

import yaml

job_file, halo4d, scene, out, shards = sys.argv[1:6]
job = yaml.safe_load(open(job_file))
assert job["apiVersion"] == "batch/v1" and job["kind"] == "Job", "not a batch/v1 Job"
spec = job["spec"]
assert spec["completionMode"] == "Indexed", "not an Indexed Job"
(container,) = spec["template"]["spec"]["containers"]
env = {e["name"]: e["value"] for e in container["env"]}
assert int(env["SHARDS"]) == spec["completions"], "SHARDS is not the completion count"
command = container["command"] + container["args"]
env.update(SCENE=scene, OUT=out, SHARDS=shards, RAYON_NUM_THREADS="1")
# The image's `halo4d` is this build's.
path = os.path.dirname(os.path.abspath(halo4d)) + os.pathsep + os.environ["PATH"]
pods = [
    subprocess.Popen(
        command, env={**os.environ, **env, "PATH": path, "JOB_COMPLETION_INDEX": str(i)}
    )
    for i in range(int(shards))
]
codes = [p.wait() for p in pods]
assert codes == [0] * len(pods), f"pods exited {codes}"
print(f"{len(pods)} pods of {job_file} completed")
