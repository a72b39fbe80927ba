"""The reference IEMA node's start outside ROS, for tests/usecases/iema/test_real_cells.py.

The node (``scripts/gearbox_handler_cabling.py`` of the ROS 1 package ``database_wires``) runs as
it is under a Python 2.7 with numpy, enum34, xmltodict and pyexcel-ods. What it needs of ROS and
of PyKDL is written here as Python 2.7 modules, into a temporary folder at run time:

- ``PyKDL``: ``Vector``, ``Rotation`` and ``Frame`` with the operations the node uses, computed as
  KDL computes them (``Rotation.Quaternion`` without normalising, ``DoRotX`` about the moving axis,
  ``GetQuaternion`` by KDL's own branches); a member read is the member itself and a member
  assignment copies, as in the SIP bindings;
- ``rospy``: parameters from the launch file, services kept by name, a main loop that runs once;
- ``tf``: a transform tree, so ``lookupTransform`` answers what the node itself broadcast in its
  loop, under the launch file's static ``world → gearbox_rf``;
- the message modules (``geometry_msgs``, ``std_msgs``, ``std_srvs``, ``visualization_msgs``, and
  the package's own ``database_wires.msg``/``.srv``, read from its ``msg/`` and ``srv/`` files);
- ``cv2``, which the node's ``transformations`` module imports and its start does not use.

The driver runs the node's script to its main loop, lets the loop turn once (it broadcasts the
gearbox and duct frames the providers look up), then calls the services it registered, in order,
and prints their answers as JSON on its last line.
"""

from __future__ import annotations

__all__ = ["DRIVER", "stub_files"]

PYKDL = r'''
"""PyKDL's geometry, as KDL computes it, for the operations the node uses."""
import math


class Vector(object):
    def __init__(self, x=0.0, y=0.0, z=0.0):
        self.v = [float(x), float(y), float(z)]

    def _coordinate(self, i, value):
        if value is None:
            return self.v[i]
        self.v[i] = float(value)

    def x(self, value=None):
        return self._coordinate(0, value)

    def y(self, value=None):
        return self._coordinate(1, value)

    def z(self, value=None):
        return self._coordinate(2, value)

    def __getitem__(self, i):
        return self.v[i]

    def __setitem__(self, i, value):
        self.v[i] = float(value)

    def __add__(self, other):
        return Vector(*[a + b for a, b in zip(self.v, other.v)])

    def __sub__(self, other):
        return Vector(*[a - b for a, b in zip(self.v, other.v)])

    def __neg__(self):
        return Vector(*[-a for a in self.v])

    def __mul__(self, other):
        if isinstance(other, Vector):  # KDL: the cross product
            a, b = self.v, other.v
            return Vector(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
        return Vector(*[a * other for a in self.v])

    __rmul__ = __mul__

    def __div__(self, value):
        return Vector(*[a / value for a in self.v])

    __truediv__ = __div__

    def Norm(self):
        return math.sqrt(sum(a * a for a in self.v))

    def Normalize(self):
        norm = self.Norm()
        if norm:
            self.v = [a / norm for a in self.v]
        return norm

    def __repr__(self):
        return "[%r, %r, %r]" % tuple(self.v)


class Rotation(object):
    def __init__(self, *values):
        if len(values) == 9:
            self.m = [[float(v) for v in values[i:i + 3]] for i in (0, 3, 6)]
        elif len(values) == 3:  # three column vectors
            self.m = [[values[j][i] for j in range(3)] for i in range(3)]
        else:
            self.m = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]

    def __getitem__(self, index):
        return self.m[index[0]][index[1]]

    def __setitem__(self, index, value):
        self.m[index[0]][index[1]] = float(value)

    def __mul__(self, other):
        if isinstance(other, Vector):
            return Vector(*[sum(self.m[i][k] * other.v[k] for k in range(3)) for i in range(3)])
        product = [sum(self.m[i][k] * other.m[k][j] for k in range(3)) for i in range(3) for j in range(3)]
        return Rotation(*product)

    def Inverse(self):
        return Rotation(*[self.m[j][i] for i in range(3) for j in range(3)])

    def DoRotX(self, angle):
        self.m = (self * Rotation.RotX(angle)).m

    def DoRotY(self, angle):
        self.m = (self * Rotation.RotY(angle)).m

    def DoRotZ(self, angle):
        self.m = (self * Rotation.RotZ(angle)).m

    @staticmethod
    def Identity():
        return Rotation()

    @staticmethod
    def RotX(angle):
        c, s = math.cos(angle), math.sin(angle)
        return Rotation(1, 0, 0, 0, c, -s, 0, s, c)

    @staticmethod
    def RotY(angle):
        c, s = math.cos(angle), math.sin(angle)
        return Rotation(c, 0, s, 0, 1, 0, -s, 0, c)

    @staticmethod
    def RotZ(angle):
        c, s = math.cos(angle), math.sin(angle)
        return Rotation(c, -s, 0, s, c, 0, 0, 0, 1)

    @staticmethod
    def RPY(roll, pitch, yaw):
        return Rotation.RotZ(yaw) * Rotation.RotY(pitch) * Rotation.RotX(roll)

    @staticmethod
    def Quaternion(x, y, z, w):
        # As KDL: not normalised.
        x2, y2, z2, w2 = x * x, y * y, z * z, w * w
        return Rotation(
            w2 + x2 - y2 - z2, 2 * x * y - 2 * w * z, 2 * x * z + 2 * w * y,
            2 * x * y + 2 * w * z, w2 - x2 + y2 - z2, 2 * y * z - 2 * w * x,
            2 * x * z - 2 * w * y, 2 * y * z + 2 * w * x, w2 - x2 - y2 + z2,
        )

    def GetQuaternion(self):
        m = self.m
        trace = m[0][0] + m[1][1] + m[2][2]
        if trace > 1e-12:
            s = 0.5 / math.sqrt(trace + 1.0)
            return ((m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s)
        if m[0][0] > m[1][1] and m[0][0] > m[2][2]:
            s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
            return (0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
        if m[1][1] > m[2][2]:
            s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
            return ((m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        return ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s)

    def UnitX(self):
        return Vector(self.m[0][0], self.m[1][0], self.m[2][0])

    def UnitY(self):
        return Vector(self.m[0][1], self.m[1][1], self.m[2][1])

    def UnitZ(self):
        return Vector(self.m[0][2], self.m[1][2], self.m[2][2])


def _copy(value):
    if isinstance(value, Vector):
        return Vector(*value.v)
    return Rotation(*[a for row in value.m for a in row])


class Frame(object):
    # A subclass may skip this constructor (the node's Transform does): its members then start
    # as KDL's defaults when first read.
    def __init__(self, *args):
        for arg in args:
            if isinstance(arg, Rotation):
                self.M = arg
            elif isinstance(arg, Vector):
                self.p = arg

    def _member(self, name, default):
        if name not in self.__dict__:
            self.__dict__[name] = default()
        return self.__dict__[name]

    def _set(self, name, value):
        self.__dict__[name] = _copy(value)

    p = property(lambda self: self._member("_p", Vector), lambda self, v: self._set("_p", v))
    M = property(lambda self: self._member("_M", Rotation), lambda self, v: self._set("_M", v))

    def __mul__(self, other):
        if isinstance(other, Vector):
            return self.M * other + self.p
        return Frame(self.M * other.M, self.M * other.p + self.p)

    def Inverse(self):
        inverse = self.M.Inverse()
        return Frame(inverse, -(inverse * self.p))

    @staticmethod
    def Identity():
        return Frame()
'''

MESSAGES = r'''
"""ROS messages as plain objects: fields from message definitions, defaults as ROS gives them."""
import re

PRIMITIVES = {
    "bool": bool, "string": str, "float64": float, "float32": float, "int8": int, "uint8": int,
    "int16": int, "uint16": int, "int32": int, "uint32": int, "int64": int, "uint64": int,
    "time": float, "duration": float, "byte": int, "char": int,
}
TYPES = {}


class Message(object):
    _fields = ()
    _package = ""

    def __init__(self, **values):
        for kind, name in self._fields:
            setattr(self, name, values[name] if name in values else _default(kind, self._package))

    def __getattr__(self, name):
        # Fields of messages not defined here (visualization markers) come as they are asked for.
        if name.startswith("_"):
            raise AttributeError(name)
        value = Message()
        setattr(self, name, value)
        return value


def _default(kind, package):
    if kind.endswith("]"):
        return []
    if kind in PRIMITIVES:
        return PRIMITIVES[kind]()
    return TYPES[_resolve(kind, package)]()


def _resolve(kind, package):
    if kind == "Header":
        return "std_msgs/Header"
    return kind if "/" in kind else package + "/" + kind


def fields(text):
    found = []
    for line in text.splitlines():
        line = line.split("#")[0].strip()
        if line and "=" not in line and not re.match(r"^-{3,}$", line):
            kind, name = line.split()[:2]
            found.append((kind, name))
    return tuple(found)


def define(package, name, text, base=Message, **constants):
    attributes = dict(constants, _fields=fields(text), _package=package)
    kind = type(str(name), (base,), attributes)
    TYPES[package + "/" + name] = kind
    return kind


def plain(value):
    if isinstance(value, Message):
        return dict((k, plain(v)) for k, v in sorted(value.__dict__.items()))
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def build(kind, values):
    message = kind()
    for name, value in values.items():
        current = getattr(message, name)
        setattr(message, name, build(type(current), value) if isinstance(value, dict) else value)
    return message


define("std_msgs", "Header", "uint32 seq\ntime stamp\nstring frame_id")
define("geometry_msgs", "Point", "float64 x\nfloat64 y\nfloat64 z")
define("geometry_msgs", "Vector3", "float64 x\nfloat64 y\nfloat64 z")
define("geometry_msgs", "Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w")
define("geometry_msgs", "Pose", "Point position\nQuaternion orientation")
define("geometry_msgs", "Twist", "Vector3 linear\nVector3 angular")
'''

GEOMETRY_MSGS = """from rosmessages import TYPES
NAMES = ("Point", "Pose", "Quaternion", "Twist", "Vector3")
Point, Pose, Quaternion, Twist, Vector3 = (TYPES["geometry_msgs/" + n] for n in NAMES)
"""
STD_MSGS = """from rosmessages import TYPES, define
Header = TYPES["std_msgs/Header"]
String = define("std_msgs", "String", "string data")
Float64 = define("std_msgs", "Float64", "float64 data")
"""
STD_SRVS = """from rosmessages import define
class Trigger(object):
    pass
TriggerRequest = define("std_srvs", "TriggerRequest", "")
TriggerResponse = define("std_srvs", "TriggerResponse", "bool success\\nstring message")
"""
VISUALIZATION_MSGS = """from rosmessages import define
Marker = define("visualization_msgs", "Marker", "Point[] points", ARROW=0, MESH_RESOURCE=10, ADD=0)
MarkerArray = define("visualization_msgs", "MarkerArray", "Marker[] markers")
"""
# The package's own messages and services, from its msg/ and srv/ files.
PACKAGE_MESSAGES = """import os
import re
import geometry_msgs.msg
import std_msgs.msg
{imports}from rosmessages import define
FOLDER = {folder!r}
__all__ = []
for _file in sorted(os.listdir(os.path.join(FOLDER, {kind!r}))):
    _name, _suffix = os.path.splitext(_file)
    _text = open(os.path.join(FOLDER, {kind!r}, _file)).read()
    if _suffix == ".msg":
        globals()[_name] = define("database_wires", _name, _text)
        __all__.append(_name)
    elif _suffix == ".srv":
        _request, _response = (re.split(r"(?m)^-{{3,}}\\s*$", _text) + [""])[:2]
        globals()[_name] = type(_name, (object,), {{}})
        globals()[_name + "Request"] = define("database_wires", _name + "Request", _request)
        globals()[_name + "Response"] = define("database_wires", _name + "Response", _response)
        __all__ += [_name, _name + "Request", _name + "Response"]
"""
ROSPY = '''
"""rospy for a node run outside ROS: parameters, services by name, a main loop that runs once."""
PARAMS = {}
SERVICES = {}
LOOPS = [1]


class Time(object):
    def __init__(self, secs=0, nsecs=0):
        self.secs, self.nsecs = secs, nsecs

    @staticmethod
    def now():
        return Time()


def get_rostime():
    return Time()


def init_node(*args, **kwargs):
    pass


def get_param(name, default=None):
    return PARAMS.get(name.lstrip("~"), default)


class Publisher(object):
    def __init__(self, *args, **kwargs):
        pass

    def publish(self, message):
        pass


class Rate(object):
    def __init__(self, hz):
        pass

    def sleep(self):
        pass


def Service(name, kind, handler):
    SERVICES[name] = handler


def is_shutdown():
    LOOPS[0] -= 1
    return LOOPS[0] < 0


def loginfo(*args):
    pass


logwarn = logerr = logdebug = loginfo
'''
TF = '''
"""tf for a node run outside ROS: a tree of the transforms broadcast, looked up through it."""
import PyKDL

TREE = {}


def _frame(translation, rotation):
    frame = PyKDL.Frame()
    frame.p = PyKDL.Vector(*translation)
    frame.M = PyKDL.Rotation.Quaternion(*rotation)
    return frame


class LookupException(Exception):
    pass


class TransformBroadcaster(object):
    def sendTransform(self, translation, rotation, time, child, parent):
        TREE[child.strip("/")] = (parent.strip("/"), _frame(translation, rotation))


class TransformListener(object):
    def lookupTransform(self, target, source, time):
        """The pose of frame ``source`` in frame ``target`` (an ancestor of it in the tree)."""
        frame, name = PyKDL.Frame(), source.strip("/")
        while name != target.strip("/"):
            if name not in TREE:
                raise LookupException("%s is not connected to %s" % (source, target))
            name, link = TREE[name]
            frame = link * frame
        return ((frame.p.x(), frame.p.y(), frame.p.z()), frame.M.GetQuaternion())
'''

DRIVER = r"""
import json
import os
import sys

stubs, scripts, plan = sys.argv[1:4]
sys.path[:0] = [stubs, scripts]
import rospy
import tf
import database_wires.srv as srv
import std_srvs.srv as std_srvs
import rosmessages

setup = json.load(open(plan))
rospy.PARAMS.update(setup["params"])
# The launch file's static_transform_publisher: where the node's gearbox_rf sits in its world.
xyz, quaternion = setup["gearbox_rf"]
tf.TransformBroadcaster().sendTransform(xyz, quaternion, rospy.Time(0), "gearbox_rf", "world")
# execfile, not runpy: runpy empties the module's globals when it returns, and the services
# registered are the module's functions.
script = os.path.join(scripts, "gearbox_handler_cabling.py")
node = {"__name__": "__main__", "__file__": script}
execfile(script, node)
answers = []
for name, kind, values in setup["requests"]:
    module = std_srvs if kind == "Trigger" else srv
    request = rosmessages.build(getattr(module, kind + "Request"), values)
    try:
        answers.append(["ok", rosmessages.plain(rospy.SERVICES["gearbox_handler/" + name](request))])
    except Exception as error:
        answers.append(["error", "%s: %s" % (type(error).__name__, error)])
print(json.dumps({"answers": answers, "services": sorted(rospy.SERVICES)}))
"""


def stub_files(node_package: str) -> dict[str, str]:
    """The stub modules by their path in the stub folder; ``node_package`` is the folder of the
    node's package (holding ``msg/`` and ``srv/``)."""
    return {
        "PyKDL.py": PYKDL,
        "rospy.py": ROSPY,
        "tf.py": TF,
        "cv2.py": "# imported by the node's transformations module; its start uses none of it\n",
        "rosmessages.py": MESSAGES,
        "geometry_msgs/__init__.py": "",
        "geometry_msgs/msg.py": GEOMETRY_MSGS,
        "std_msgs/__init__.py": "",
        "std_msgs/msg.py": STD_MSGS,
        "std_srvs/__init__.py": "",
        "std_srvs/srv.py": STD_SRVS,
        "visualization_msgs/__init__.py": "",
        "visualization_msgs/msg.py": VISUALIZATION_MSGS,
        "database_wires/__init__.py": "",
        "database_wires/msg.py": PACKAGE_MESSAGES.format(folder=node_package, kind="msg", imports=""),
        "database_wires/srv.py": PACKAGE_MESSAGES.format(
            folder=node_package, kind="srv", imports="import database_wires.msg\n"
        ),
    }
