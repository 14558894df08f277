"""The operators: `twister.render` (a still, shown as an Image and written to the output
folder) and `twister.render_animation` (the frame range as numbered frames, in the background,
with progress; Esc stops it between frames). Each refusal is one line in the info bar and
CANCELLED; Blender never sees an exception."""

from __future__ import annotations

import os
import subprocess
import tempfile

import bpy

from . import props, run, scene_export
from . import settings as s


def prepare(context, animation: bool = False):
    """(scene file, settings, output folder, warnings, temporary folder) or raises ValueError
    with the line to report."""
    scene = context.scene
    if scene.camera is None:
        raise ValueError("the scene has no active camera: twister draws from the camera's place")
    if not scene_export.has_geometry(scene):
        raise ValueError("the scene has nothing visible to render")
    camera = scene_export.camera_settings(scene)
    world, warnings = scene_export.world_settings(scene)
    settings, more = s.render_settings(scene.twister.values(), camera, world)
    warnings += more + scene_export.unsupported(scene)
    if run.package() is None and run.command(props.preferences(context)) is None:
        raise ValueError("twister not found: install its Python package into Blender's Python, or set its command in the preferences")
    out = bpy.path.abspath(scene.twister.output_dir)
    tmp = tempfile.TemporaryDirectory(prefix="twister-blender-")
    path = scene_export.export(scene, tmp.name, animation)
    return path, settings, out, warnings, tmp


def show(paths):
    """Loads the written images into Blender (Image datablocks), the first in an Image Editor."""
    images = []
    for p in paths:
        if p.lower().endswith((".png", ".jpg")):
            images.append(bpy.data.images.load(p, check_existing=True))
            images[-1].reload()
    screen = bpy.context.screen
    for area in (screen.areas if screen else []):
        if area.type == "IMAGE_EDITOR" and images:
            area.spaces.active.image = images[0]
    return images


class TWISTER_OT_render(bpy.types.Operator):
    """Render the scene's omnidirectional stereo with twister"""

    bl_idname = "twister.render"
    bl_label = "Render with twister"

    def execute(self, context):
        try:
            path, settings, out, warnings, tmp = prepare(context)
        except ValueError as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        for w in warnings:
            self.report({"WARNING"}, w)
        try:
            with tmp:
                written = run.render_still(path, out, settings, props.preferences(context))
        except (ValueError, OSError, RuntimeError) as e:
            self.report({"ERROR"}, str(e).splitlines()[0] if str(e) else type(e).__name__)
            return {"CANCELLED"}
        show(written)
        self.report({"INFO"}, f"twister: {len(written)} files in {out}")
        return {"FINISHED"}


class TWISTER_OT_render_animation(bpy.types.Operator):
    """Render the scene's frame range with twister (Esc stops it between frames)"""

    bl_idname = "twister.render_animation"
    bl_label = "Render animation with twister"

    _process = None
    _frames = None
    _timer = None
    _tmp = None

    def execute(self, context):
        scene = context.scene
        try:
            path, settings, out, warnings, tmp = prepare(context, animation=True)
            fps = scene.render.fps / scene.render.fps_base
            frames = range(scene.frame_end - scene.frame_start + 1)
            if scene.twister.video:
                # The video is the command line's (ffmpeg, spherical metadata).
                settings = dict(settings, video=os.path.join(out, "twister.mp4"))
            if run.package() is not None and not scene.twister.video:
                # The package: one frame a step, each saved whole as it finishes.
                self._frames = iter(run.renderer().render_frames(path, frames=frames, fps=fps, **settings))
            else:
                cmd = run.sequence_command(path, out, settings, list(frames), fps, props.preferences(context))
                self._process = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        except (ValueError, RuntimeError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        for w in warnings:
            self.report({"WARNING"}, w)
        self._tmp, self._out, self._total, self._done = tmp, out, len(frames), 0
        if bpy.app.background:
            while True:
                state = self._step()
                if state is not None:
                    return self._finish(state)
        wm = context.window_manager
        wm.progress_begin(0, self._total)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _step(self):
        """Advances the sequence: None while frames remain, else the error line ("" when done)."""
        if self._frames is not None:
            try:
                frame = next(self._frames)
            except StopIteration:
                return ""
            except (ValueError, OSError, RuntimeError) as e:
                return str(e) or type(e).__name__
            for f in frame.values() if isinstance(frame, dict) else [frame]:
                f.save(self._out)
            self._done += 1
            return None
        if self._process.poll() is None:
            if bpy.app.background:
                self._process.wait()
            return None
        err = self._process.stderr.read()
        if self._process.returncode != 0:
            return (err.strip().splitlines() or ["twister stopped"])[-1].removeprefix("error: ")
        self._done = self._total
        return ""

    def _finish(self, error):
        self._tmp.cleanup()
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        self.report({"INFO"}, f"twister: {self._total} frames in {self._out}")
        return {"FINISHED"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            # Frames are written whole (each by a rename): stopping leaves none half-written.
            if self._process is not None:
                self._process.terminate()
                self._process.wait()
            self._tmp.cleanup()
            wm.event_timer_remove(self._timer)
            wm.progress_end()
            self.report({"WARNING"}, "twister: stopped; the frames already written are whole")
            return {"CANCELLED"}
        if event.type == "TIMER":
            state = self._step()
            if self._process is not None and os.path.isdir(self._out):
                self._done = len([f for f in os.listdir(self._out) if f.startswith("frame_")]) // 2
            wm.progress_update(min(self._done, self._total))
            if state is not None:
                wm.event_timer_remove(self._timer)
                wm.progress_end()
                return self._finish(state)
        return {"PASS_THROUGH"}


class TWISTER_PT_settings(bpy.types.Panel):
    bl_label = "twister"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "output"

    def draw(self, context):
        t = context.scene.twister
        col = self.layout.column()
        for name in ("panorama", "layout", "method", "width", "height", "samples", "anisotropy"):
            col.prop(t, name)
        col.prop(t, "eyes_from_camera")
        sub = col.column()
        sub.enabled = not t.eyes_from_camera
        sub.prop(t, "eye_radius")
        for name in ("output_dir", "format", "depth", "video"):
            col.prop(t, name)
        row = col.row()
        row.operator("twister.render", icon="RENDER_STILL")
        row.operator("twister.render_animation", icon="RENDER_ANIMATION")


CLASSES = (TWISTER_OT_render, TWISTER_OT_render_animation, TWISTER_PT_settings)


def register():
    for c in CLASSES:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(CLASSES):
        bpy.utils.unregister_class(c)
