#pragma once
// Headless MP4 recording: MuJoCo renders offscreen into an EGL context on Mesa's software
// renderer (no X server, no GPU), raw RGB frames go through a pipe into ffmpeg (libx264).
// Slow (~40 ms per 640x480 frame): optional in every run.

#include <mujoco/mujoco.h>

#include <cstdio>
#include <string>
#include <vector>

namespace hqp::sim {

class VideoRecorder {
 public:
  // Throws std::runtime_error when EGL, the MuJoCo context or ffmpeg cannot be started.
  // Two views side by side, both following `track_body`'s subtree centre of mass: from the front
  // (foot and torso roll) and from the right side (pitch; the right foot is the one the moving
  // supports drive). `title` (the scenario) is captioned in every frame.
  VideoRecorder(const mjModel* m, const std::string& path, int width, int height, int fps, int track_body,
                const std::string& title = {});
  ~VideoRecorder();
  VideoRecorder(const VideoRecorder&) = delete;
  VideoRecorder& operator=(const VideoRecorder&) = delete;

  // Render the current state, with the title, the time and an optional caption (the latest push),
  // and append it.
  void frame(mjData* d, const std::string& caption = {});
  // The run stopped at a fall: the current state with "FALL at t = ...: reason", held for
  // `hold_s` so that the last picture can be read.
  void fall(mjData* d, double time, const std::string& reason, double hold_s = 2.0);
  int frames() const { return frames_; }
  double fps() const { return fps_; }

 private:
  void render(mjData* d, const std::string& caption, const std::string& banner, const std::string& detail);
  void write();

  const mjModel* m_;
  int width_, height_, frames_ = 0;
  double fps_;
  int track_body_;
  std::string title_;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  mjvScene scene_;
  mjvCamera cameras_[2];  // front, right side
  mjvOption option_;
  mjrContext context_mj_;
  std::vector<unsigned char> rgb_;
  FILE* pipe_ = nullptr;
};

}  // namespace hqp::sim
