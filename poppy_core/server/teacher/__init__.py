"""The teacher's page (``poppy fleet serve``): one card per robot of a Zenoh fleet, commands to a
selection with the fleet's shared start, one Stop for all; ``create_teacher_app``,
``TeacherServer``."""

from poppy_core.server.teacher.app import TeacherServer, create_teacher_app, exposure

__all__ = ["TeacherServer", "create_teacher_app", "exposure"]
