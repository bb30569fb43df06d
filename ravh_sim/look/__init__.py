"""What the camera should see, as plain data between the world and the renderers: geometry and
materials, the lights, and what changed since a revision."""
