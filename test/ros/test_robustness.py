#!/usr/bin/python3
"""The node stays up and reports bad input (NaN, out-of-order stamps, silence) and exits with a clear message on
bad parameters; its settings change through dynamic_reconfigure only when allowed, validated by the core."""
import math
import os
import signal
import subprocess
import threading
import time
import unittest

import dynamic_reconfigure.client
import rosgraph
import roslib.packages
import rospy
import rostest
import yaml
from diagnostic_msgs.msg import DiagnosticArray
from hunting_monitor.msg import HuntingAlarm, HuntingStatus
from nodelet.srv import NodeletList
from sensor_msgs.msg import Imu
from std_msgs.msg import Float64


class Robustness(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_robustness")
        cls.lock = threading.Lock()
        cls.status, cls.diag, cls.rc_status = [], [], []
        rospy.Subscriber("hunting_status", HuntingStatus, cls.keep(cls.status), queue_size=1000)
        rospy.Subscriber("/rc/hunting_status", HuntingStatus, cls.keep(cls.rc_status), queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.keep(cls.diag), queue_size=100)
        cls.accel = rospy.Publisher("accel", Imu, queue_size=1000)
        cls.speed = rospy.Publisher("speed", Float64, queue_size=10)
        time.sleep(2.0)  # connections

    @classmethod
    def keep(cls, store):
        def cb(msg):
            with cls.lock:
                store.append(msg)
        return cb

    def stream(self, seconds, value=None, stamp_offset=0.0, speed=400.0, amplitude=2.0):
        """Publish lateral acceleration at 500 Hz (a 14 Hz sine of `amplitude`, or `value`) and speed at 10 Hz, in real
        time."""
        start = time.time()
        k = 0
        while time.time() - start < seconds:
            now = rospy.Time.now()
            m = Imu()
            m.header.stamp = now + rospy.Duration(stamp_offset)
            m.linear_acceleration.y = amplitude * math.sin(2 * math.pi * 14.0 * now.to_sec()) if value is None else value
            self.accel.publish(m)
            if k % 50 == 0:
                self.speed.publish(Float64(speed))
            k += 1
            time.sleep(0.002)

    def assert_normal(self, m, history=()):
        """400 km/h (or 360) is far below the Hopf speed: OK; WATCH only for the rate this test publishes at (a
        Python loop in real time, not quite the configured rate), which the node must then have measured: in this
        status or, as the alarm holds a level for min_hold_s (3 s) after its cause clears, before (`history`: the
        statuses received)."""
        if m.level == HuntingStatus.LEVEL_WATCH:
            flagged = [round(x.header.stamp.to_sec() - m.header.stamp.to_sec(), 2) for x in history
                       if x.sample_rate_mismatch]
            self.assertTrue(m.reason_code == 13 and (m.sample_rate_mismatch or flagged),
                            (m.level, m.reason, m.sample_rate_mismatch, m.sample_rate_hz, flagged[-5:]))
        else:
            self.assertEqual(m.level, HuntingStatus.LEVEL_OK, (m.level, m.reason))
            self.assertEqual(m.reason_code, 4, m.reason)  # normal running: the bistable band is in the fields
            self.assertLess(m.margin_to_lowest_cycle_kmh, 0.0)

    def latest(self, after, store=None):
        with self.lock:
            return [m for m in (self.status if store is None else store) if m.header.stamp.to_sec() > after]

    def diag_level(self, name, after, node="/hunting_monitor"):
        with self.lock:
            hits = [s for a in self.diag if a.header.stamp.to_sec() > after for s in a.status
                    if s.name == f"{node[1:]}: {name}"]
        return hits[-1] if hits else None

    def test_1_good_data_then_nan_and_out_of_order(self):
        self.stream(3.0)
        t = rospy.Time.now().to_sec()
        self.stream(1.0)
        good = self.latest(t)
        self.assertTrue(good, "no status")
        self.assert_normal(good[-1], self.latest(0.0))
        self.assertGreater(good[-1].sample_rate_hz, 100.0)
        t = rospy.Time.now().to_sec()
        # right after good data, stamps 0.5 s in the past (within ~clock/max_step_s, so they reach the estimator):
        # out of order for their first half second; then NaN values
        self.stream(1.0, stamp_offset=-0.5)
        self.stream(1.0, value=float("nan"))
        self.stream(0.5)
        after = self.latest(t)
        self.assertTrue(after, "the node stopped publishing")
        for m in after:
            self.assertTrue(all(math.isfinite(getattr(m, f)) for f in ("amplitude_accel_mps2", "frequency_hz",
                                                                      "margin_to_hopf_kmh", "rms_accel_mps2")))
        d = self.diag_level("inputs", t)
        self.assertIsNotNone(d)
        self.assertIn(d.level, (1, 2), "rejected samples must show in the diagnostics")
        values = {kv.key: kv.value for kv in d.values}
        self.assertGreater(int(values["rejected non-finite"]), 100)
        self.assertGreater(int(values["rejected out of order"]), 100)

    def test_2_silence_is_no_data(self):
        self.stream(2.0)
        t = rospy.Time.now().to_sec()
        time.sleep(2.7)  # no acceleration, no speed (diagnostics are published once a second)
        silent = self.latest(t + 0.5)
        self.assertTrue(silent, "the node stopped publishing during the silence")
        self.assertTrue(all(m.level == HuntingStatus.LEVEL_NO_DATA and not m.boundaries_valid for m in silent),
                        [(m.level, m.boundaries_valid) for m in silent])
        d = self.diag_level("hunting level", t + 0.5)
        self.assertIsNotNone(d)
        self.assertEqual(d.level, 2)
        t = rospy.Time.now().to_sec()
        self.stream(2.0)
        back = self.latest(t + 1.0)
        self.assertTrue(back, "the node did not recover")
        self.assert_normal(back[-1], self.latest(0.0))

    def test_4_float64_accel_and_speed_in_mps(self):
        """A second node with accel_type float64 (receipt time) and speed in m/s, on its own topics, and no table
        file: it computes its table on start (36 conicities) and adds the exact family at the conicity in use (the
        vehicle's lambda(0) = 0.1358, between two of its curves) in the background."""
        with open(rospy.get_param("~vehicle_config")) as f:
            params = yaml.safe_load(f)
        for section, value in params.items():
            rospy.set_param(f"/plain/{section}", value)
        rospy.set_param("/plain/estimator", {"sample_rate_hz": 200})
        node = roslib.packages.find_node("hunting_monitor", "hunting_monitor_node")[0]
        proc = subprocess.Popen([node, "__name:=plain", "_accel_type:=float64", "_speed_unit:=mps",
                                 "accel:=plain_accel", "speed:=plain_speed", "hunting_status:=plain_status"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        got = []
        sub = rospy.Subscriber("plain_status", HuntingStatus, lambda m: got.append(m), queue_size=100)
        acc = rospy.Publisher("plain_accel", Float64, queue_size=100)
        spd = rospy.Publisher("plain_speed", Float64, queue_size=10)
        try:
            time.sleep(2.0)
            start = time.time()
            k = 0

            def done():  # a settled 10 Hz tone and the exact family added (the node's table refinement)
                return got and got[-1].oscillation_valid and abs(got[-1].frequency_hz - 10.0) < 0.3 and \
                    got[-1].table_conicities == 37
            # at least 4 s; on a loaded machine this Python publisher stalls (beyond 50 ms it is a gap and the
            # tracker settles again), so it streams until the status shows it settled, 20 s at most
            while time.time() - start < 4.0 or (not done() and time.time() - start < 20.0):
                acc.publish(Float64(2.0 * math.sin(2 * math.pi * 10.0 * (time.time() - start))))
                if k % 20 == 0:
                    spd.publish(Float64(100.0))  # m/s = 360 km/h
                k += 1
                time.sleep(0.005)
            self.assertTrue(got, "no status from the float64/m/s node")
            # the status that showed it (a later one, within 5 ms, may come from a new stall)
            last = next((m for m in reversed(got) if m.oscillation_valid and m.table_conicities == 37), got[-1])
            self.assertAlmostEqual(last.speed_kmh, 360.0, places=6)
            self.assert_normal(last, got)
            self.assertTrue(last.oscillation_valid and abs(last.frequency_hz - 10.0) < 0.3,
                            (last.oscillation_valid, last.frequency_hz, time.time() - start))
            first = next(m for m in got if m.boundaries_valid)
            self.assertEqual(first.table_conicities, 36)  # the computed table (hm_monitor_config_default)
            self.assertGreater(first.table_error_speed_kmh, 0.05)  # interpolated at 0.1358: beyond the tolerance
            self.assertEqual(last.table_conicities, 37)  # one exact family added...
            self.assertEqual(last.table_error_speed_kmh, 0.0)  # ...at the conicity in use
            self.assertAlmostEqual(last.conicity_used, 0.1358, places=9)
            self.assertAlmostEqual(last.lowest_cycle_speed_kmh, 239.549, delta=0.001)  # the fold (MODEL.md 7)
        finally:
            sub.unregister()
            proc.terminate()
            proc.wait(timeout=10)

    def test_5_dynamic_reconfigure(self):
        """Off by default (no service); allowed on /rc/hunting_monitor: a valid change is applied at once (the level
        follows), logged in diagnostics with its values; invalid ones are refused with the running settings kept."""
        services = [s for s, _ in rosgraph.Master("/test_robustness").getSystemState()[2]]
        self.assertNotIn("/hunting_monitor/set_parameters", services)
        self.assertIn("/rc/hunting_monitor/set_parameters", services)
        t = rospy.Time.now().to_sec()
        self.stream(3.5)  # 400 km/h: OK (diagnostics come once a second)
        d = self.diag_level("settings", t)
        self.assertEqual((d.level, d.message), (0, "settings as loaded (dynamic_reconfigure not allowed)"))
        d = self.diag_level("settings", t, "/rc/hunting_monitor")
        self.assertEqual((d.level, d.message), (0, "settings as loaded (dynamic_reconfigure allowed)"))
        before = self.latest(t + 2.0, self.rc_status)[-1]
        self.assertIn(before.level, (HuntingStatus.LEVEL_OK, HuntingStatus.LEVEL_WATCH), before.reason)
        margin = before.margin_to_hopf_kmh  # about 117 km/h below the Hopf speed
        self.assertGreater(margin, 50.0)

        client = dynamic_reconfigure.client.Client("/rc/hunting_monitor", timeout=10)
        loaded = client.get_configuration(timeout=10)
        self.assertEqual((loaded["warn_speed_margin_kmh"], loaded["watch_speed_margin_kmh"]), (10.0, 30.0))  # yaml
        warn, watch = round(margin) + 20.0, round(margin) + 40.0  # the running speed now inside the WARN margin
        feeder = threading.Thread(target=lambda: self.stream(3.5))
        feeder.start()
        time.sleep(0.5)
        got = client.update_configuration({"warn_speed_margin_kmh": warn, "watch_speed_margin_kmh": watch})
        changed_at = rospy.Time.now().to_sec()
        feeder.join()
        self.assertEqual((got["warn_speed_margin_kmh"], got["watch_speed_margin_kmh"]), (warn, watch))
        self.assertTrue(got["result"].startswith("applied: "), got["result"])
        after = self.latest(changed_at + 0.2, self.rc_status)
        self.assertTrue(after and all(m.level == HuntingStatus.LEVEL_WARN and m.reason_code == 5 for m in after),
                        [(m.level, m.reason) for m in after])  # near the Hopf speed, by the new margin
        self.assertTrue(all(m.level != HuntingStatus.LEVEL_WARN for m in self.latest(changed_at + 0.2)))  # not /hm
        d = self.diag_level("settings", changed_at, "/rc/hunting_monitor")
        self.assertEqual((d.level, d.message), (1, "settings changed at runtime"))
        values = {kv.key: kv.value for kv in d.values}
        self.assertEqual(values["alarm.warn_speed_margin_kmh"], f"10 -> {warn:g}")
        self.assertEqual(values["alarm.watch_speed_margin_kmh"], f"30 -> {watch:g}")

        # refused by the core's validator: the WATCH margin below the WARN margin, a negative hysteresis, a zero and
        # a negative peaks count, NaN; each answer carries the running settings and the reason
        for change, field in [({"watch_speed_margin_kmh": warn - 5.0}, "alarm.watch_speed_margin_kmh"),
                              ({"hysteresis_kmh": -1.0}, "alarm.hysteresis_kmh"),
                              ({"peaks_count": 0}, "estimator.peaks_count"),
                              ({"peaks_count": -3}, "estimator.peaks_count"),
                              ({"rms_limit_mps2": float("nan")}, "estimator.rms_limit_mps2")]:
            got = client.update_configuration(change)
            self.assertTrue(got["result"].startswith("refused: "), (change, got["result"]))
            self.assertIn(field, got["result"])
            self.assertEqual((got["warn_speed_margin_kmh"], got["watch_speed_margin_kmh"], got["hysteresis_kmh"],
                              got["peaks_count"], got["rms_limit_mps2"]), (warn, watch, 3.0, 6, 12.0), change)
        t = rospy.Time.now().to_sec()
        self.stream(2.5)
        self.assertTrue(all(m.level == HuntingStatus.LEVEL_WARN for m in self.latest(t + 0.2, self.rc_status)))
        d = self.diag_level("settings", t, "/rc/hunting_monitor")
        values = {kv.key: kv.value for kv in d.values}
        self.assertEqual((d.level, values["changes refused"], values["changes applied"]), (1, "5", "1"))
        self.assertIn("estimator.rms_limit_mps2", values["last refused"])  # the last one: NaN
        got = client.update_configuration({"warn_speed_margin_kmh": 10.0, "watch_speed_margin_kmh": 30.0})
        self.assertEqual(got["result"], "applied: settings as loaded")

    def run_bad_node(self, name, vehicle_changes, extra):
        with open(rospy.get_param("~vehicle_config")) as f:
            params = yaml.safe_load(f)
        for section, key, value in vehicle_changes:
            params[section][key] = value
        for section, value in params.items():
            rospy.set_param(f"/{name}/{section}", value)
        rospy.set_param(f"/{name}/table_file", rospy.get_param("~table"))
        node = roslib.packages.find_node("hunting_monitor", "hunting_monitor_node")[0]
        p = subprocess.run([node, f"__name:={name}"] + extra, capture_output=True, text=True, timeout=30)
        return p.returncode, p.stdout + p.stderr

    def test_3_bad_parameters_exit_with_a_message(self):
        cases = [
            ("bad_rate", [], ["_status_rate_hz:=-1"], "~status_rate_hz must be in (0, 1000]"),
            ("bad_mass", [("vehicle", "mass_kg", -1869)], [], "vehicle.mass_kg: must be > 0"),
            ("bad_type", [], ["_accel_type:=twist"], "~accel_type must be imu or float64"),
            ("bad_table", [("vehicle", "kx_mn_m", 9.7)], [], "table made for Kx 8.96"),
            ("bad_key", [("vehicle", "mas_kg", 1)], [], "vehicle.mas_kg: unknown key"),
            ("bad_time", [], ["_time_source:=gps"], "~time_source must be header or receipt"),
            ("bad_clock", [], ["_clock/window_s:=-1"], "~clock.window_s: must be in (0, 3600]"),
            ("bad_state", [], ["_state_period_s:=0"], "~state_period_s: state.period_s: must be in [0.1, 3600]"),
        ]
        for name, changes, extra, message in cases:
            code, out = self.run_bad_node(name, changes, extra)
            self.assertNotEqual(code, 0, f"{name} exited 0")
            self.assertIn(message, out, f"{name}: {out}")

    def test_3b_bad_parameters_fail_the_nodelet_load(self):
        """As a nodelet, a bad parameter fails the load (the manager runs on, without it), as the node exits 1."""
        with open(rospy.get_param("~vehicle_config")) as f:
            params = yaml.safe_load(f)
        for section, value in params.items():
            rospy.set_param(f"/bad_nodelet/{section}", value)
        rospy.set_param("/bad_nodelet/table_file", rospy.get_param("~table"))
        nodelet = roslib.packages.find_node("nodelet", "nodelet")[0]
        manager = subprocess.Popen([nodelet, "manager", "__name:=bad_manager"], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        try:
            p = subprocess.run([nodelet, "load", "hunting_monitor/MonitorNodelet", "/bad_manager",
                                "__name:=bad_nodelet", "_status_rate_hz:=-1"], capture_output=True, text=True,
                               timeout=30)
            self.assertNotEqual(p.returncode, 0, p.stdout + p.stderr)
            self.assertIn("Failed to load nodelet", p.stdout + p.stderr)
            self.assertIsNone(manager.poll(), "the manager died")
            loaded = rospy.ServiceProxy("/bad_manager/list", NodeletList)()
            self.assertEqual(list(loaded.nodelets), [])
        finally:
            manager.terminate()
            manager.wait(timeout=10)

    def test_6_a_held_alarm_says_why(self):
        """Issue #27 item 7 through the node: a 14 Hz oscillation of 20 m/s^2 at 400 km/h (r.m.s. 14 m/s^2 over the
        wheelset's 12; 2.5 mm over the 2.1 mm displacement limit) latches ALARM; calm at 400 km/h, it is held: the
        reason code the cause that latched it, the text "held (...)" with the release condition, waiting for the speed
        (the release speed the hunted-at 400 km/h less the 3 km/h hysteresis), calm 0 of 10 s; the stamped alarm and
        the level diagnostic say the same; calm at 388 km/h, released 10 s after the first status below 397 km/h.
        (The calm is a 0.2 m/s^2 tone: an exactly constant signal has no crossings, and the tracker keeps its last
        amplitude, a stuck sensor read as the oscillation it last saw.)"""
        stamped = []
        sub = rospy.Subscriber("hunting_alarm_stamped", HuntingAlarm, lambda m: stamped.append(m), queue_size=100)
        try:
            self.stream(2.0)
            self.stream(3.0, amplitude=20.0)
            t = rospy.Time.now().to_sec()
            self.stream(5.0, amplitude=0.2)  # (the tracker needs 2-3 s to follow the drop from 20 to 0.2 m/s^2)
            held = [m for m in self.latest(t + 3.5) if m.level_held]
            self.assertTrue(held, [(m.level, m.reason) for m in self.latest(t)][-3:])
            m = held[-1]
            self.assertEqual((m.level, m.level_latched, m.reason_code), (HuntingStatus.LEVEL_ALARM, True,
                                                                         m.hold_cause_code))
            self.assertIn(m.hold_cause_code, (9, 10, 15), m.hold_cause)  # r.m.s., peaks, displacement
            self.assertTrue(m.reason.startswith("held (" + m.hold_cause), m.reason)
            self.assertIn("hunting seen down to 400.0 km/h", m.reason)
            self.assertIn("releases below 397.0 km/h after 10 s calm (calm 0.0 s: waits for the speed", m.reason)
            self.assertAlmostEqual(m.hunted_at_kmh, 400.0, delta=1e-9)
            self.assertAlmostEqual(m.hold_release_below_kmh, 397.0, delta=1e-9)
            self.assertEqual((m.hold_calm_s, m.hold_calm_needed_s, m.hold_waits), (0.0, 10.0,
                                                                                   HuntingStatus.HOLD_WAITS_SPEED))
            self.assertGreater(m.hold_since.to_sec(), 0.0)
            self.assertLessEqual(m.hold_since.to_sec(), m.hold_last_met.to_sec())
            a = [x for x in stamped if x.level_held]
            self.assertTrue(a and a[-1].reason.startswith("held (") and a[-1].hold_release_below_kmh == 397.0,
                            [(x.level, x.reason) for x in stamped[-3:]])
            d = self.diag_level("hunting level", t + 3.5)
            self.assertTrue(d is not None and "held (" in d.message, d)
            t = rospy.Time.now().to_sec()
            for v in (396.0, 392.0, 388.0):  # within the estimator's plausible change of the speed
                self.stream(0.1, amplitude=0.2, speed=v)
            self.stream(11.5, amplitude=0.2, speed=388.0)
            after = self.latest(t)
            below = next(x for x in after if x.speed_kmh < 397.0)
            released = next((x for x in after if not x.level_latched), None)
            self.assertIsNotNone(released, [(x.level, x.reason) for x in after[-2:]])
            self.assertAlmostEqual(released.header.stamp.to_sec() - below.header.stamp.to_sec(), 10.0, delta=0.5)
        finally:
            sub.unregister()

    def test_7_restart_keeps_what_was_learned(self):
        """A monitor at 480 km/h (the simulator, 35 km/h below the Hopf speed) identifies the conicity; killed (SIGKILL:
        only its periodic state file survives) and started again, its first status with data has the interval it had
        before (exactly, that of its status when it last wrote the file: one in its last state_period_s + 1 s) and the
        same level, the diagnostics say
        "restored, age ...". Stopped (SIGINT: it writes at shutdown), its file truncated: the next start refuses it
        and restores the previous one (FILE.prev). The first start, with no file, is the control: the prior."""
        with open(rospy.get_param("~vehicle_config")) as f:
            params = yaml.safe_load(f)
        for section, value in params.items():
            rospy.set_param(f"/restart_monitor/{section}", value)
            rospy.set_param(f"/restart_sim/{section}", value)
        rospy.set_param("/restart_monitor/table_file", rospy.get_param("~table"))
        for key, value in (("v_start_kmh", 480.0), ("v_end_kmh", 480.0), ("ramp_s", 0.0), ("hold_s", 240.0),
                           ("irregularity_scale", 0.1), ("seed", 7)):
            rospy.set_param(f"/restart_sim/{key}", value)
        # the node's default file (under ROS_HOME, named after it); a leftover of an earlier run removed
        home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
        path = os.path.join(home, "hunting_monitor_state", "restart_monitor")
        for p in (path, path + ".prev"):
            if os.path.exists(p):
                os.remove(p)
        topics = ["accel:=/restart/accel", "speed:=/restart/speed"]
        outputs = [f"{t}:=/restart/{t}" for t in ("hunting_status", "hunting_alarm", "hunting_alarm_stamped",
                                                  "hunting_markers", "hunting_chart")]
        node = roslib.packages.find_node("hunting_monitor", "hunting_monitor_node")[0]
        sim = roslib.packages.find_node("hunting_monitor", "hunting_sim_node")[0]
        got, diag = [], []
        lock = threading.Lock()

        def keep(store):
            def cb(msg):
                with lock:
                    store.append((time.time(), msg))
            return cb
        subs = [rospy.Subscriber("/restart/hunting_status", HuntingStatus, keep(got), queue_size=1000),
                rospy.Subscriber("/diagnostics", DiagnosticArray, keep(diag), queue_size=100)]

        def start():
            return subprocess.Popen([node, "__name:=restart_monitor"] + topics + outputs, stdout=subprocess.DEVNULL,
                                    stderr=subprocess.DEVNULL)

        def since(t0, store=got):
            with lock:
                return [m for t, m in store if t >= t0]

        def state_diag(t0):
            hits = [s for a in since(t0, diag) for s in a.status if s.name == "restart_monitor: state file"]
            return hits[-1] if hits else None

        def first_valid(t0, timeout):
            end = time.time() + timeout
            while time.time() < end:
                valid = [m for m in since(t0) if m.boundaries_valid]
                if valid:
                    return valid[0]
                time.sleep(0.1)
            return None

        def wait_for(cond, timeout):
            end = time.time() + timeout
            while time.time() < end and not cond():
                time.sleep(0.2)
            return cond()
        procs = [subprocess.Popen([sim, "__name:=restart_sim"] + topics, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)]
        try:
            t_a = time.time()
            a = start()
            procs.append(a)
            fresh = first_valid(t_a, 30.0)
            self.assertIsNotNone(fresh, "no status with data from the first start")
            self.assertTrue(fresh.conicity_from_prior and fresh.level == HuntingStatus.LEVEL_WARN,
                            (fresh.level, fresh.reason, fresh.hopf_speed_kmh_low))  # the control: the prior
            self.assertTrue(wait_for(lambda: state_diag(t_a) is not None and
                                     state_diag(t_a).message.startswith("no state file yet"), 10.0),
                            state_diag(t_a) and state_diag(t_a).message)
            self.assertTrue(wait_for(lambda: any(m.conicity_from_estimate for m in since(t_a)), 70.0),
                            "the first start did not identify the conicity")
            t_identified = time.time() - t_a

            def settled():  # the last 5 s identified at one level (the level lowered from the prior's WARN after its
                # min_hold_s), and a periodic write since
                recent = [m for m in since(time.time() - 5.0) if m.boundaries_valid]
                return time.time() - t_a > t_identified + 5.0 and len(recent) > 50 and \
                    all(m.conicity_from_estimate and m.level == recent[-1].level for m in recent)
            self.assertTrue(wait_for(settled, 30.0), "the level did not settle")
            t_kill = time.time()
            a.kill()  # SIGKILL at speed: no shutdown write
            a.wait(timeout=10)
            before = [m for m in since(t_kill - 3.0) if m.boundaries_valid]
            self.assertTrue(before and all(m.conicity_from_estimate for m in before), "not identified before the kill")
            t_b = time.time()
            b = start()
            procs.append(b)
            first = first_valid(t_b, 30.0)
            self.assertIsNotNone(first, "no status with data after the restart")
            n_before_first = len([m for m in since(t_b) if m.header.stamp < first.header.stamp])
            self.assertTrue(first.conicity_from_estimate, (first.level, first.reason, first.hopf_speed_kmh_low))
            self.assertEqual(first.level, before[-1].level, (first.reason, before[-1].reason))
            match = min(before, key=lambda m: abs(m.hopf_speed_kmh_low - first.hopf_speed_kmh_low) +
                        abs(m.hopf_speed_kmh_high - first.hopf_speed_kmh_high))
            self.assertAlmostEqual(first.hopf_speed_kmh_low, match.hopf_speed_kmh_low, delta=1e-6)
            self.assertAlmostEqual(first.hopf_speed_kmh_high, match.hopf_speed_kmh_high, delta=1e-6)
            self.assertTrue(wait_for(lambda: state_diag(t_b) is not None and
                                     state_diag(t_b).message.startswith("restored, age "), 10.0),
                            state_diag(t_b) and state_diag(t_b).message)
            restored_b = state_diag(t_b)
            time.sleep(3.0)
            b.send_signal(signal.SIGINT)  # stopped: it writes at shutdown
            b.wait(timeout=20)
            with open(path, "rb") as f:
                record = f.read()
            with open(path, "wb") as f:
                f.write(record[: len(record) // 2])
            t_c = time.time()
            c = start()
            procs.append(c)
            third = first_valid(t_c, 30.0)
            self.assertIsNotNone(third, "no status with data after the third start")
            self.assertTrue(third.conicity_from_estimate, (third.level, third.reason))
            self.assertTrue(wait_for(lambda: state_diag(t_c) is not None and
                                     state_diag(t_c).message.startswith(f"restored from {path}.prev"), 10.0),
                            state_diag(t_c) and state_diag(t_c).message)
            restored_c = state_diag(t_c)
            self.assertIn(f"{path}: truncated: {len(record) // 2} of {len(record)} bytes", restored_c.message)
            self.assertEqual(restored_c.level, 1)  # WARN: the file was damaged
            t_written = time.time()
            self.assertTrue(wait_for(lambda: int(dict((v.key, v.value) for v in state_diag(t_written).values)["writes"])
                                     > 0 if state_diag(t_written) else False, 10.0), "no write after the restore")
            took = {v.key: v.value for v in state_diag(t_written).values}["last write took [ms]"]
            names = {0: "NO_DATA", 1: "OK", 2: "WATCH", 3: "WARN", 4: "ALARM"}
            print(f"  identified {t_identified:.1f} s after the first start (the prior: {names[fresh.level]}); killed: "
                  f"[{before[-1].hopf_speed_kmh_low:.3f}, {before[-1].hopf_speed_kmh_high:.3f}] "
                  f"{names[before[-1].level]}; restarted: first status with data "
                  f"{first.header.stamp.to_sec() - t_b:.1f} s after the start ({n_before_first} before it without data), [{first.hopf_speed_kmh_low:.3f}, "
                  f"{first.hopf_speed_kmh_high:.3f}] {names[first.level]} (the killed one's "
                  f"{t_kill - match.header.stamp.to_sec():.1f} s before the kill); '{restored_b.message}'; truncated: "
                  f"'{restored_c.message}'; a write took {took} ms")
        finally:
            for sub in subs:
                sub.unregister()
            for p in reversed(procs):
                if p.poll() is None:
                    p.terminate()
                    p.wait(timeout=20)


if __name__ == "__main__":
    rostest.rosrun("hunting_monitor", "robustness", Robustness)
