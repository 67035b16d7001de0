// glfw_window.cpp — GLFW window front end (OpenGL 4.3 core context) for `caustica view`.
