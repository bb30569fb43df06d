"""How images are made: the one place that knows renderers.

``backend.py`` chooses the backend (our OpenGL renderer on an EGL context, or pybullet's
TinyRenderer when no GL is available); ``gl_renderer.py`` is the physically based renderer (shadows,
local lights, procedural materials, windows onto an outdoor backdrop, auto-exposure) with a
``realistic`` and a ``fast`` quality; ``geometry.py`` turns the World's meshes into vertex arrays;
``materials.py`` says what each palette colour and paint is made of. Cameras (ravh_sim.sensors)
ask a renderer for RGB, depth and instance images from one optical pose and never talk GL.
"""
