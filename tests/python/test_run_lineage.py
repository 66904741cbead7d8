"""Run lineage (docs/guarantees.md, "One run per directory"): every run has a random run id,
stored in its restart files (kairos/run/id) and summary.json (run_id) and kept by every run
continued from them. A continued run appends to the outputs of a directory only when they are of
its own lineage (cut back to the restart point first, wherever the restart file lies); the
outputs of another run are refused unless --overwrite, which starts them afresh from the restart
point.
"""

import os
import re
import shutil

import numpy as np

import kairos_testlib as kt


def config(seed, directory="out"):
    c = kt.base_config(particles=300, packing_fraction=0.3, seed=seed, directory=directory)
    c["run"] = {"equilibration_time": 0.0, "time": 2.0}
    c["output"].update({"thermo_interval": 0.1, "trajectory_interval": 0.5})
    return c


def run_id_of(restart):
    return bytes(kt.restart_chunk(restart, "kairos/run/id").astype(np.uint8)).decode()


def read(path):
    with open(path, "rb") as f:
        return f.read()


def frame_times(path):
    return [float(f.log["time"][0]) for f in kt.open_trajectory(path)]


class RunIds(kt.KairosTestCase):
    def test_the_run_id_is_random_and_kept_across_continuations(self):
        cfg = self.write_config(config(3))
        a, b, c = self.path("a"), self.path("b"), self.path("c")
        self.run_ok("run", cfg, "-o", a)
        self.run_ok("run", cfg, "-o", b)  # the same config and seed: another run all the same
        ida = self.summary(a)["run_id"]
        self.assertRegex(ida, r"^[0-9a-f]{32}$")
        self.assertEqual(run_id_of(os.path.join(a, "restart.gsd")), ida)
        self.assertNotEqual(self.summary(b)["run_id"], ida)
        # Continued into its own directory and into a new one: the same lineage.
        self.run_ok("run", cfg, "--restart", os.path.join(a, "restart.gsd"), "-o", c)
        self.run_ok("run", cfg, "--restart", os.path.join(a, "restart.gsd"), "-o", a)
        for d in (a, c):
            self.assertEqual(self.summary(d)["run_id"], ida)
            self.assertEqual(run_id_of(os.path.join(d, "restart.gsd")), ida)


class ContinuedIntoADirectory(kt.KairosTestCase):
    def setUp(self):
        super().setUp()
        self.cfg = self.write_config(config(3))
        self.a = self.path("a")
        self.run_ok("run", self.cfg, "-o", self.a)
        self.restart = os.path.join(self.a, "restart.gsd")

    def test_another_runs_directory_is_refused_unless_overwrite(self):
        b = self.path("b")
        self.run_ok("run", self.write_config(config(5), "b.toml"), "-o", b)
        before = {name: read(os.path.join(b, name)) for name in ("thermo.tsv", "trajectory.gsd")}
        result = self.kairos("run", self.cfg, "--restart", self.restart, "-o", b)
        self.assert_user_error(result, "'%s'" % b, "another run", self.summary(b)["run_id"],
                               self.summary(self.a)["run_id"], "--overwrite")
        for name, data in before.items():
            self.assertEqual(read(os.path.join(b, name)), data, name + " was changed")
        # A restart file copied into the other run's directory is no evidence of what it holds.
        shutil.copy(self.restart, os.path.join(b, "restart.gsd"))
        result = self.kairos("run", self.cfg, "--restart", os.path.join(b, "restart.gsd"), "-o", b)
        self.assert_user_error(result, "another run", self.summary(b)["run_id"])
        # --overwrite: b's outputs start afresh from the restart point, as in an empty directory.
        self.run_ok("run", self.cfg, "--restart", self.restart, "-o", b, "--overwrite")
        empty = self.path("empty")
        self.run_ok("run", self.cfg, "--restart", self.restart, "-o", empty)
        self.assertEqual(read(os.path.join(b, "thermo.tsv")),
                         read(os.path.join(empty, "thermo.tsv")))
        self.assertEqual(frame_times(os.path.join(b, "trajectory.gsd")),
                         frame_times(os.path.join(empty, "trajectory.gsd")))
        self.assertGreaterEqual(frame_times(os.path.join(b, "trajectory.gsd"))[0], 2.0)
        self.assertEqual(self.summary(b)["run_id"], self.summary(self.a)["run_id"])

    def test_outputs_without_a_run_id_elsewhere_are_refused(self):
        # Outputs of an older Kairos (no run id anywhere) in another directory: the continued run
        # cannot tell they are its own.
        b = self.path("b")
        self.run_ok("run", self.write_config(config(5), "b.toml"), "-o", b)
        os.remove(os.path.join(b, "restart.gsd"))
        os.remove(os.path.join(b, "summary.json"))
        result = self.kairos("run", self.cfg, "--restart", self.restart, "-o", b)
        self.assert_user_error(result, "'%s'" % b, "no run id", "--overwrite")

    def test_a_saved_restart_file_continues_its_lineage_without_duplicated_rows(self):
        # A copy of the restart file kept elsewhere, then the run extended in its directory;
        # continuing the copy into that directory again must drop what came after the copy's
        # state (the same continuation again), not append to it.
        saved = self.path("saved")
        os.mkdir(saved)
        shutil.copy(self.restart, os.path.join(saved, "restart.gsd"))
        self.run_ok("run", self.cfg, "--restart", self.restart, "-o", self.a)
        once = {name: read(os.path.join(self.a, name)) for name in ("thermo.tsv",)}
        times = frame_times(os.path.join(self.a, "trajectory.gsd"))
        self.run_ok("run", self.cfg, "--restart", os.path.join(saved, "restart.gsd"), "-o", self.a)
        self.assertEqual(read(os.path.join(self.a, "thermo.tsv")), once["thermo.tsv"],
                         "rows after the saved state were kept (duplicated)")
        self.assertEqual(frame_times(os.path.join(self.a, "trajectory.gsd")), times)
        row_times = [row[1] for row in kt.read_thermo(os.path.join(self.a, "thermo.tsv"))[1]]
        self.assertEqual(row_times, sorted(set(row_times)))

    def test_a_continuation_without_a_trajectory_cuts_it_back_to_the_restart_point(self):
        # The run extended to t = 4, then continued again from its state at t = 2 with
        # output.trajectory = false: the frames after t = 2 are the extension's and must go.
        saved = self.path("saved")
        os.mkdir(saved)
        shutil.copy(self.restart, os.path.join(saved, "restart.gsd"))
        at_restart = frame_times(os.path.join(self.a, "trajectory.gsd"))
        self.run_ok("run", self.cfg, "--restart", self.restart, "-o", self.a)
        self.assertGreater(len(frame_times(os.path.join(self.a, "trajectory.gsd"))),
                           len(at_restart))
        self.run_ok("run", self.cfg, "--restart", os.path.join(saved, "restart.gsd"), "-o", self.a,
                    "--set", "output.trajectory=false")
        self.assertEqual(frame_times(os.path.join(self.a, "trajectory.gsd")), at_restart)
        # Its restart file records those frames, for the next continuation.
        outputs = kt.restart_chunk(self.restart, "kairos/run/outputs")
        self.assertEqual(int(outputs[1]), len(at_restart))
        # The rows of thermo.tsv were cut back as well, and continued to t = 4 once.
        rows = kt.read_thermo(os.path.join(self.a, "thermo.tsv"))[1]
        self.assertEqual(len(rows), 40)

    def test_an_older_restart_file_without_a_run_id_still_continues_its_directory(self):
        chunks = kt.read_frame_chunks(self.restart)
        del chunks["kairos/run/id"]
        kt.write_frame_chunks(self.restart, chunks)
        self.run_ok("run", self.cfg, "--restart", self.restart, "-o", self.a)
        s = self.summary(self.a)
        self.assertTrue(s["restarted"])
        self.assertRegex(s["run_id"], r"^[0-9a-f]{32}$")  # a new lineage from here on

    def test_a_corrupt_run_id_is_refused(self):
        chunks = kt.read_frame_chunks(self.restart)
        chunks["kairos/run/id"] = np.frombuffer(b"../x\n", np.int8)
        kt.write_frame_chunks(self.restart, chunks)
        result = self.kairos("run", self.cfg, "--restart", self.restart, "-o", self.path("c"))
        self.assert_user_error(result, self.restart, "kairos/run/id")


if __name__ == "__main__":
    kt.main()
