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
  // The camera tracks `track_body` (its subtree's centre of mass) from the side-front.
  VideoRecorder(const mjModel* m, const std::string& path, int width, int height, int fps, int track_body);
  ~VideoRecorder();
  VideoRecorder(const VideoRecorder&) = delete;
  VideoRecorder& operator=(const VideoRecorder&) = delete;

  // Render the current state, with the time and an optional caption (the latest push), and append it.
  void frame(mjData* d, const std::string& caption = {});
  int frames() const { return frames_; }
  double fps() const { return fps_; }

 private:
  const mjModel* m_;
  int width_, height_, frames_ = 0;
  double fps_;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  mjvScene scene_;
  mjvCamera camera_;
  mjvOption option_;
  mjrContext context_mj_;
  std::vector<unsigned char> rgb_;
  FILE* pipe_ = nullptr;
};

}  // namespace hqp::sim
