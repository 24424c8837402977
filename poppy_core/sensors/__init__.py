"""Sensors: cameras (OpenCV, blank, simulated), markers, faces, blobs, devices, IMUs, OptiTrack.

Imports nothing of ours but ``errors``; OpenCV, gpiozero and smbus2 are imported on first use.
The robot factory builds them from a config's ``sensors`` section (``build_sensors``).
"""

from poppy_core.sensors.arduino import ArduinoSensor
from poppy_core.sensors.base import Sensor, SensorHealth, SensorLost
from poppy_core.sensors.blobs import Blob, BlobDetector
from poppy_core.sensors.bno055 import BNO055
from poppy_core.sensors.camera import Camera, CameraCalibration, DummyCamera, Frame
from poppy_core.sensors.config import (
    NOT_YET,
    SUPPORTED_TYPES,
    SensorSpec,
    build_sensors,
    dummy_camera,
    opencv_camera,
)
from poppy_core.sensors.contact import ContactSensor
from poppy_core.sensors.detector import FrameDetector, MarkerDetector
from poppy_core.sensors.faces import Face, FaceDetector, FaceFinder
from poppy_core.sensors.imu import Imu, RazorIMU, StillIMU
from poppy_core.sensors.kinect import KinectSensor, Skeleton, skeleton_sensors
from poppy_core.sensors.markers import Marker, MarkerFinder, MarkerPose, marker_image
from poppy_core.sensors.optibridge import OptiBridgeClient, OptiBridgeServer
from poppy_core.sensors.optitrack import OptiTrackClient, TrackedObject
from poppy_core.sensors.pose import PoseSkeleton
from poppy_core.sensors.sonar import SonarSensor

__all__ = [
    "BNO055",
    "NOT_YET",
    "SUPPORTED_TYPES",
    "ArduinoSensor",
    "Blob",
    "BlobDetector",
    "Camera",
    "CameraCalibration",
    "ContactSensor",
    "DummyCamera",
    "Face",
    "FaceDetector",
    "FaceFinder",
    "Frame",
    "FrameDetector",
    "Imu",
    "KinectSensor",
    "Marker",
    "MarkerDetector",
    "MarkerFinder",
    "MarkerPose",
    "OptiBridgeClient",
    "OptiBridgeServer",
    "OptiTrackClient",
    "PoseSkeleton",
    "RazorIMU",
    "Sensor",
    "SensorHealth",
    "SensorLost",
    "SensorSpec",
    "Skeleton",
    "SonarSensor",
    "StillIMU",
    "TrackedObject",
    "build_sensors",
    "dummy_camera",
    "marker_image",
    "opencv_camera",
    "skeleton_sensors",
]
