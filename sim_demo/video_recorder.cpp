#include "video_recorder.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hqp::sim {

namespace {

// The first EGL device display that initialises (Mesa's software device on a headless machine).
EGLDisplay openDisplay() {
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!query_devices || !platform_display) throw std::runtime_error("EGL device extensions are missing");
  EGLDeviceEXT devices[8];
  EGLint n = 0;
  if (!query_devices(8, devices, &n) || n < 1) throw std::runtime_error("no EGL device");
  for (EGLint i = 0; i < n; ++i) {
    EGLDisplay dpy = platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
    EGLint major = 0, minor = 0;
    if (dpy != EGL_NO_DISPLAY && eglInitialize(dpy, &major, &minor)) return dpy;
  }
  throw std::runtime_error("no EGL device display initialises");
}

}  // namespace

VideoRecorder::VideoRecorder(const mjModel* m, const std::string& path, int width, int height, int fps,
                             int track_body, const std::string& title)
    : m_(m), width_(width), height_(height), fps_(fps), track_body_(std::max(0, track_body)), title_(title) {
  EGLDisplay dpy = openDisplay();
  display_ = dpy;
  // Without EGL_PBUFFER_BIT no config is found on Mesa's device platform.
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8,
                                   EGL_BLUE_SIZE, 8, EGL_ALPHA_SIZE, 8, EGL_DEPTH_SIZE, 24,
                                   EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config;
  EGLint nconfig = 0;
  if (!eglChooseConfig(dpy, config_attribs, &config, 1, &nconfig) || nconfig < 1) {
    throw std::runtime_error("no EGL config for offscreen OpenGL");
  }
  eglBindAPI(EGL_OPENGL_API);
  EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, nullptr);
  if (ctx == EGL_NO_CONTEXT) throw std::runtime_error("eglCreateContext failed");
  context_ = ctx;
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) throw std::runtime_error("eglMakeCurrent failed");

  mjv_defaultScene(&scene_);
  for (mjvCamera& c : cameras_) mjv_defaultCamera(&c);
  mjv_defaultOption(&option_);
  mjr_defaultContext(&context_mj_);
  mjv_makeScene(m, &scene_, 2000);
  mjr_makeContext(m, &context_mj_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_mj_);
  if (context_mj_.offWidth < width_ || context_mj_.offHeight < height_) {
    width_ = context_mj_.offWidth;  // <visual><global offwidth offheight> of the scene
    height_ = context_mj_.offHeight;
  }
  // Free cameras whose look-at point follows the robot (render()): azimuth is the direction the
  // camera looks in, so 160 deg looks back at the robot's front from slightly to its right and
  // 110 deg at its right side from slightly to the front; the 20 deg offsets keep depth visible.
  // Low elevation: foot roll and pitch show as tilted soles against the floor.
  const double azimuth[2] = {160.0, 110.0};
  for (int i = 0; i < 2; ++i) {
    cameras_[i].type = mjCAMERA_FREE;
    cameras_[i].distance = 2.6;  // the whole 1.6 m robot in a half-width (portrait) panel
    cameras_[i].azimuth = azimuth[i];
    cameras_[i].elevation = -8.0;
  }
  rgb_.resize(static_cast<std::size_t>(3) * width_ * height_);

  const std::string cmd = "ffmpeg -loglevel error -y -f rawvideo -pix_fmt rgb24 -s " + std::to_string(width_) + "x" +
                          std::to_string(height_) + " -r " + std::to_string(fps) +
                          " -i - -vf vflip -c:v libx264 -pix_fmt yuv420p -crf 23 '" + path + "'";
  pipe_ = popen(cmd.c_str(), "w");
  if (!pipe_) throw std::runtime_error("cannot start ffmpeg (install it: apt-get install --no-install-recommends ffmpeg)");
}

VideoRecorder::~VideoRecorder() {
  if (pipe_) pclose(pipe_);
  mjr_freeContext(&context_mj_);
  mjv_freeScene(&scene_);
  auto dpy = static_cast<EGLDisplay>(display_);
  eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_) eglDestroyContext(dpy, static_cast<EGLContext>(context_));
  eglTerminate(dpy);
}

void VideoRecorder::render(mjData* d, const std::string& caption, const std::string& banner,
                           const std::string& detail) {
  const mjrRect full{0, 0, width_, height_};
  const int half = width_ / 2;
  const mjrRect panel[2] = {{0, 0, half, height_}, {half, 0, width_ - half, height_}};
  for (int i = 0; i < 2; ++i) {
    // Follow the robot's centre of mass over the floor at a fixed height, so that crouching or
    // falling does not move the horizon.
    cameras_[i].lookat[0] = d->subtree_com[3 * track_body_];
    cameras_[i].lookat[1] = d->subtree_com[3 * track_body_ + 1];
    cameras_[i].lookat[2] = 0.75;
    if (i == 0) mjv_updateScene(m_, d, &option_, nullptr, &cameras_[0], mjCAT_ALL, &scene_);
    else mjv_updateCamera(m_, d, &cameras_[i], &scene_);  // same geoms, other viewpoint
    mjr_render(panel[i], &scene_, &context_mj_);
  }
  mjr_rectangle({half - 1, 0, 2, height_}, 0.1f, 0.1f, 0.1f, 1.0f);  // divider
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMLEFT, panel[0], "front", nullptr, &context_mj_);
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMLEFT, panel[1], "right side", nullptr, &context_mj_);
  if (banner.empty()) {
    char t[32];
    std::snprintf(t, sizeof(t), "t = %.2f s", d->time);
    const std::string label = title_.empty() ? std::string(t) : title_ + "\n" + t;
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, full, label.c_str(), nullptr, &context_mj_);
    if (!caption.empty()) mjr_overlay(mjFONT_BIG, mjGRID_TOPRIGHT, full, caption.c_str(), nullptr, &context_mj_);
  } else {
    // Across the top, where it hides sky rather than the hips and feet; two lines because a long
    // reason does not fit one line of the big font.
    const std::string second = title_.empty() ? detail : title_ + ": " + detail;
    mjr_label({0, height_ - 44, width_, 44}, mjFONT_BIG, banner.c_str(), 0.75f, 0.08f, 0.08f, 0.9f, 1, 1, 1,
              &context_mj_);
    mjr_label({0, height_ - 80, width_, 36}, mjFONT_BIG, second.c_str(), 0.75f, 0.08f, 0.08f, 0.9f, 1, 1, 1,
              &context_mj_);
  }
  mjr_readPixels(rgb_.data(), nullptr, full, &context_mj_);
}

void VideoRecorder::write() {
  // OpenGL rows run bottom-up; ffmpeg's vflip turns them the right way.
  if (std::fwrite(rgb_.data(), 1, rgb_.size(), pipe_) != rgb_.size()) throw std::runtime_error("ffmpeg pipe closed");
  ++frames_;
}

void VideoRecorder::frame(mjData* d, const std::string& caption) {
  render(d, caption, {}, {});
  write();
}

void VideoRecorder::fall(mjData* d, double time, const std::string& reason, double hold_s) {
  char banner[64];
  std::snprintf(banner, sizeof(banner), "FALL at t = %.2f s", time);
  render(d, {}, banner, reason);
  const int n = std::max(1, static_cast<int>(std::lround(hold_s * fps_)));
  for (int i = 0; i < n; ++i) write();  // one rendering, held
}

}  // namespace hqp::sim
