#!/usr/bin/python3
"""Time that jumps: the node notices ROS time moving backwards (a restarted or looped bag) and a sensor clock jumping
forwards, resets the monitor, says so in the log and diagnostics, and monitors again within its settling time (1 s
tracking + 1 s rate measurement here), never stuck in NO_DATA."""
import math
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from hunting_monitor.msg import HuntingStatus
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu
from std_msgs.msg import Float64

RATE = 500.0  # Hz of the simulated accelerometer


class TimeJump(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_timejump")
        cls.lock = threading.Lock()
        cls.status, cls.diag = [], []
        cls.clock = rospy.Publisher("/clock", Clock, queue_size=10)
        cls.accel = rospy.Publisher("accel", Imu, queue_size=1000)
        cls.speed = rospy.Publisher("speed", Float64, queue_size=10)
        rospy.Subscriber("hunting_status", HuntingStatus, cls.keep(cls.status), queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.keep(cls.diag), queue_size=100)
        cls.publish_clock(1000.0)
        time.sleep(2.0)  # connections

    @classmethod
    def keep(cls, store):
        def cb(msg):
            with cls.lock:
                store.append(msg)
        return cb

    @classmethod
    def publish_clock(cls, t):
        cls.clock.publish(Clock(clock=rospy.Time.from_sec(t)))

    def run_stream(self, t0, seconds, stamp_offset=0.0):
        """Simulated time from t0 for `seconds`, paced at real time: clock, a 14 Hz Imu stream at RATE and speed."""
        n = int(seconds * RATE)
        start = time.time()
        for k in range(n):
            t = t0 + k / RATE
            self.publish_clock(t)
            m = Imu()
            m.header.stamp = rospy.Time.from_sec(t + stamp_offset)
            m.linear_acceleration.y = 2.0 * math.sin(2 * math.pi * 14.0 * t)
            self.accel.publish(m)
            if k % 50 == 0:
                self.speed.publish(Float64(400.0))
            lag = start + k / RATE - time.time()
            if lag > 0:
                time.sleep(lag)
        time.sleep(0.3)

    def mark(self):
        with self.lock:
            return len(self.status), len(self.diag)

    def since(self, mark):
        with self.lock:
            return self.status[mark[0]:], self.diag[mark[1]:]

    def assert_monitoring_again(self, statuses, t_jump, settle):
        """Level NO_DATA at most `settle` seconds of simulated time after the jump, monitoring after."""
        after = [m for m in statuses if m.header.stamp.to_sec() >= t_jump]
        self.assertTrue(after, "no status after the jump")
        late = [m for m in after if m.header.stamp.to_sec() >= t_jump + settle]
        self.assertTrue(late, "the stream was too short")
        self.assertTrue(all(m.level != HuntingStatus.LEVEL_NO_DATA for m in late),
                        [(round(m.header.stamp.to_sec() - t_jump, 2), m.level, m.reason) for m in late][:10])

    def jump_reported(self, diags, text):
        return any(text in s.message and s.level == 1 for a in diags for s in a.status if "inputs" in s.name)

    def test_1_ros_time_backwards_and_sensor_clock_forwards(self):
        self.run_stream(1000.0, 4.0)
        before, _ = self.since((0, 0))
        self.assertTrue(before and before[-1].level != HuntingStatus.LEVEL_NO_DATA, "not monitoring at first")
        # the bag starts again: ROS time back to 500 s
        mark = self.mark()
        self.run_stream(500.0, 4.0)
        statuses, diags = self.since(mark)
        self.assert_monitoring_again(statuses, 500.0, 2.5)
        self.assertTrue(self.jump_reported(diags, "ROS time moved backwards"), "the jump is not in the diagnostics")
        # the sensor's clock jumps an hour ahead while ROS time goes on
        mark = self.mark()
        self.run_stream(504.0, 5.0, stamp_offset=3600.0)
        statuses, diags = self.since(mark)
        self.assert_monitoring_again(statuses, 504.0, 3.5)
        self.assertTrue(self.jump_reported(diags, "sensor stamps"), "the re-anchoring is not in the diagnostics")
        last = statuses[-1]
        self.assertAlmostEqual(last.speed_kmh, 400.0)
        self.assertTrue(last.oscillation_valid and abs(last.frequency_hz - 14.0) < 0.2, last.frequency_hz)


if __name__ == "__main__":
    rostest.rosrun("hunting_monitor", "timejump", TimeJump)
