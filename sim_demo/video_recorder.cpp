#include "video_recorder.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>

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
                             int track_body)
    : m_(m), width_(width), height_(height), fps_(fps) {
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
  mjv_defaultCamera(&camera_);
  mjv_defaultOption(&option_);
  mjr_defaultContext(&context_mj_);
  mjv_makeScene(m, &scene_, 2000);
  mjr_makeContext(m, &context_mj_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_mj_);
  if (context_mj_.offWidth < width_ || context_mj_.offHeight < height_) {
    width_ = context_mj_.offWidth;  // <visual><global offwidth offheight> of the scene
    height_ = context_mj_.offHeight;
  }
  camera_.type = mjCAMERA_TRACKING;
  camera_.trackbodyid = track_body;
  camera_.distance = 3.2;
  camera_.azimuth = 120.0;  // from the front-left, so pitch and roll both show
  camera_.elevation = -12.0;
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

void VideoRecorder::frame(mjData* d, const std::string& caption) {
  const mjrRect viewport{0, 0, width_, height_};
  mjv_updateScene(m_, d, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  mjr_render(viewport, &scene_, &context_mj_);
  char label[64];
  std::snprintf(label, sizeof(label), "t = %.2f s", d->time);
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport, label, nullptr, &context_mj_);
  if (!caption.empty()) mjr_overlay(mjFONT_BIG, mjGRID_TOPRIGHT, viewport, caption.c_str(), nullptr, &context_mj_);
  mjr_readPixels(rgb_.data(), nullptr, viewport, &context_mj_);
  // OpenGL rows run bottom-up; ffmpeg's vflip turns them the right way.
  if (std::fwrite(rgb_.data(), 1, rgb_.size(), pipe_) != rgb_.size()) throw std::runtime_error("ffmpeg pipe closed");
  ++frames_;
}

}  // namespace hqp::sim
