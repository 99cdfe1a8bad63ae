"""ardupilot_model.py -- what ArduPilot's MAVLink proximity backend makes of OBSTACLE_DISTANCE, modelled
for tests from reading its code (libraries/AP_Proximity: AP_Proximity_MAV, AP_Proximity_Boundary_3D);
written here, not copied.

The model, as read:
- The sector width is `increment_f`, else `increment`; with neither the message is dropped. At most
  72 entries are read (360 / width, rounded).
- An entry of 0, of 65535, below `min_distance` or above `max_distance` (so also "clear",
  max + 1) is skipped: it neither sets nor clears anything.
- Entry j points at (j * width + angle_offset + PRXn_YAW_CORR) degrees, wrapped to 0..360.
- The horizontal boundary has eight 45-degree faces centred on 0, 45, ..., 315 degrees; a bearing
  b is in face floor(((b + 22.5) mod 360) / 45).
- The entries are walked in order; consecutive valid entries in one face form a run and keep its
  nearest; when a valid entry falls in another face, the run ends and its face is set to that
  nearest. A face met in two runs of one message keeps the second run's value.
- The sensor is NoData when no message has come for 0.5 s; a face not set for 1 s is forgotten.
"""

NODATA_S = 0.5
FACE_EXPIRY_S = 1.0


def face_of(bearing_deg):
    return int(((bearing_deg + 22.5) % 360.0) // 45.0)


class Proximity:
    def __init__(self, yaw_correction=0.0):
        self.yaw_correction = yaw_correction
        self.faces = [None] * 8  # (metres, bearing, time set)
        self.last_msg = None
        self.messages = 0

    def obstacle_distance(self, m, t):
        """Feeds one decoded OBSTACLE_DISTANCE (pymavlink object) that arrived at time t (seconds)."""
        width = m.increment_f if m.increment_f != 0 else float(m.increment)
        if width == 0:
            return
        n = min(int(360.0 / abs(width) + 0.5), 72)
        self.last_msg = t
        self.messages += 1
        face, best = None, None
        for j in range(n):
            d = m.distances[j]
            if d == 0 or d == 65535 or d < m.min_distance or d > m.max_distance:
                continue
            bearing = (j * width + m.angle_offset + self.yaw_correction) % 360.0
            f = face_of(bearing)
            if f != face:
                self._set(face, best, t)
                face, best = f, None
            if best is None or d / 100.0 < best[0]:
                best = (d / 100.0, bearing)
        self._set(face, best, t)

    def _set(self, face, best, t):
        if face is not None and best is not None:
            self.faces[face] = (best[0], best[1], t)

    def status(self, t):
        return "NoData" if self.last_msg is None or t - self.last_msg > NODATA_S else "Good"

    def distances(self, t):
        """Each face's distance in metres at time t, or None (never set, or expired)."""
        return [None if f is None or t - f[2] > FACE_EXPIRY_S else f[0] for f in self.faces]
