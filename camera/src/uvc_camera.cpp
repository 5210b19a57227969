#include "tofguard/camera/uvc_camera.hpp"

#include <libusb-1.0/libusb.h>
#include <libuvc/libuvc.h>
#include <cstdio>
#include <cstring>

namespace tofguard::camera {
namespace {

std::string hex4(int id) {
  char text[8];
  std::snprintf(text, sizeof text, "%04x", id & 0xffff);
  return text;
}

std::string install_hint() {
  return std::string("install the udev rule: sudo cp ") + kUdevRule +
         " /etc/udev/rules.d/ && sudo udevadm control --reload-rules && sudo udevadm trigger, "
         "then replug the camera (and add the user to group plugdev)";
}

// The interface number of the first VideoStreaming interface (class 0x0e,
// subclass 0x02) of the open device; -1 if none.
int first_streaming_interface(uvc_device_handle_t* handle) {
  libusb_device_handle* usb = uvc_get_libusb_handle(handle);
  libusb_config_descriptor* config = nullptr;
  if (libusb_get_active_config_descriptor(libusb_get_device(usb), &config) != 0) return -1;
  int found = -1;
  for (int i = 0; i < config->bNumInterfaces && found < 0; ++i) {
    const libusb_interface& interface = config->interface[i];
    for (int a = 0; a < interface.num_altsetting; ++a) {
      const libusb_interface_descriptor& d = interface.altsetting[a];
      if (d.bInterfaceClass == 0x0e && d.bInterfaceSubClass == 0x02) {
        found = d.bInterfaceNumber;
        break;
      }
    }
  }
  libusb_free_config_descriptor(config);
  return found;
}

// Fills `ctrl` for a format libuvc has no enum for (Z16): looks the format
// up by FourCC in the first VideoStreaming interface's descriptors and
// probes the frame of the wanted size with the interval nearest the rate.
uvc_error_t stream_ctrl_by_fourcc(uvc_device_handle_t* handle, uvc_stream_ctrl_t* ctrl, const char* fourcc,
                                  int width, int height, double rate_hz, std::string* why) {
  for (const uvc_format_desc_t* format = uvc_get_format_descs(handle); format != nullptr;
       format = format->next) {
    if (format->bDescriptorSubtype != UVC_VS_FORMAT_UNCOMPRESSED ||
        std::memcmp(format->fourccFormat, fourcc, 4) != 0) {
      continue;
    }
    for (const uvc_frame_desc_t* frame = format->frame_descs; frame != nullptr; frame = frame->next) {
      if (frame->wWidth != width || frame->wHeight != height) continue;
      std::memset(ctrl, 0, sizeof *ctrl);
      ctrl->bmHint = 1;  // keep dwFrameInterval fixed
      ctrl->bFormatIndex = format->bFormatIndex;
      ctrl->bFrameIndex = frame->bFrameIndex;
      ctrl->dwFrameInterval = static_cast<uint32_t>(1e7 / rate_hz + 0.5);  // 100 ns units
      const int interface = first_streaming_interface(handle);
      if (interface < 0) {
        *why = "the camera has no VideoStreaming interface";
        return UVC_ERROR_INVALID_MODE;
      }
      ctrl->bInterfaceNumber = static_cast<uint8_t>(interface);
      return uvc_probe_stream_ctrl(handle, ctrl);
    }
    *why = std::string("format ") + fourcc + " has no " + std::to_string(width) + "x" +
           std::to_string(height) + " frame";
    return UVC_ERROR_INVALID_MODE;
  }
  *why = std::string("the camera's first VideoStreaming interface has no ") + fourcc + " format";
  return UVC_ERROR_INVALID_MODE;
}

// Whether a device vendor:product is attached but cannot be opened for lack
// of permission (libuvc then cannot read its serial number or open it).
bool attached_without_permission(int vendor_id, int product_id) {
  libusb_context* usb = nullptr;
  if (libusb_init(&usb) != 0) return false;
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(usb, &list);
  bool denied = false;
  for (ssize_t i = 0; i < count && !denied; ++i) {
    libusb_device_descriptor d;
    if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
    if (d.idVendor != vendor_id || d.idProduct != product_id) continue;
    libusb_device_handle* handle = nullptr;
    const int rc = libusb_open(list[i], &handle);
    if (rc == LIBUSB_ERROR_ACCESS) denied = true;
    if (rc == 0) libusb_close(handle);
  }
  if (count >= 0) libusb_free_device_list(list, 1);
  libusb_exit(usb);
  return denied;
}

}  // namespace

std::string list_usb_devices() {
  libusb_context* usb = nullptr;
  const int rc = libusb_init(&usb);
  if (rc != 0) return std::string("cannot list USB devices: libusb: ") + libusb_error_name(rc);
  libusb_device** list = nullptr;
  const ssize_t count = libusb_get_device_list(usb, &list);
  std::string text;
  if (count < 0) {
    text = std::string("cannot list USB devices: libusb: ") + libusb_error_name(static_cast<int>(count));
  } else if (count == 0) {
    text = "USB devices found: none";
    // An empty list is still allocated (its terminating null): freed too.
    libusb_free_device_list(list, 1);
  } else {
    text = "USB devices found:";
    for (ssize_t i = 0; i < count; ++i) {
      libusb_device_descriptor d;
      if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
      text += (i ? ", " : " ") + hex4(d.idVendor) + ":" + hex4(d.idProduct);
      libusb_device_handle* handle = nullptr;
      unsigned char product[128] = {0};
      // The product string needs the device opened; without permission
      // only the ids are shown.
      if (d.iProduct != 0 && libusb_open(list[i], &handle) == 0) {
        if (libusb_get_string_descriptor_ascii(handle, d.iProduct, product, sizeof product) > 0) {
          text += std::string(" \"") + reinterpret_cast<const char*>(product) + "\"";
        }
        libusb_close(handle);
      }
    }
    libusb_free_device_list(list, 1);
  }
  libusb_exit(usb);
  return text;
}

UvcCamera::UvcCamera(const CameraSettings& camera, const UvcSettings& uvc, FrameHandler on_frame)
    : camera_(camera),
      uvc_(uvc),
      format_(parse_raw_depth_format(uvc.format)),
      radial_to_z_(camera.intrinsics),
      on_frame_(std::move(on_frame)) {}

UvcCamera::~UvcCamera() { close(); }

std::string UvcCamera::device_name() const {
  return hex4(uvc_.vendor_id) + ":" + hex4(uvc_.product_id) +
         (uvc_.serial.empty() ? "" : " serial " + uvc_.serial);
}

UvcOpenResult UvcCamera::open(std::string* message) {
  close();
  uvc_error_t rc = uvc_init(&context_, nullptr);
  if (rc != UVC_SUCCESS) {
    context_ = nullptr;
    *message = std::string("cannot start libuvc: ") + uvc_strerror(rc) + "; " + list_usb_devices();
    return rc == UVC_ERROR_NO_DEVICE || rc == UVC_ERROR_IO ? UvcOpenResult::kNoDevice
                                                           : UvcOpenResult::kFailed;
  }
  rc = uvc_find_device(context_, &device_, uvc_.vendor_id, uvc_.product_id,
                       uvc_.serial.empty() ? nullptr : uvc_.serial.c_str());
  if (rc != UVC_SUCCESS) {
    device_ = nullptr;
    close();
    if (attached_without_permission(uvc_.vendor_id, uvc_.product_id)) {
      *message = "camera " + device_name() + ": permission denied; " + install_hint();
      return UvcOpenResult::kPermissionDenied;
    }
    *message = "no UVC camera " + device_name() + " attached; " + list_usb_devices();
    return UvcOpenResult::kNoDevice;
  }
  rc = uvc_open(device_, &handle_);
  if (rc != UVC_SUCCESS) {
    handle_ = nullptr;
    const bool denied = rc == UVC_ERROR_ACCESS;
    close();
    *message =
        "camera " + device_name() + ": " +
        (denied ? "permission denied; " + install_hint() : std::string("cannot open: ") + uvc_strerror(rc));
    return denied ? UvcOpenResult::kPermissionDenied : UvcOpenResult::kFailed;
  }
  const Intrinsics& in = camera_.intrinsics;
  uvc_stream_ctrl_t ctrl;
  std::string why;
  if (format_ == RawDepthFormat::kZ16) {
    rc = stream_ctrl_by_fourcc(handle_, &ctrl, fourcc(format_), in.width, in.height, camera_.rate_hz, &why);
  } else {
    rc = uvc_get_stream_ctrl_format_size(handle_, &ctrl, UVC_FRAME_FORMAT_GRAY16, in.width, in.height,
                                         static_cast<int>(camera_.rate_hz + 0.5));
  }
  if (rc != UVC_SUCCESS) {
    close();
    *message = "camera " + device_name() + " cannot stream " + uvc_.format + " " + std::to_string(in.width) +
               "x" + std::to_string(in.height) + " at " + std::to_string(camera_.rate_hz) +
               " Hz: " + (why.empty() ? uvc_strerror(rc) : why);
    return UvcOpenResult::kFailed;
  }
  rc = uvc_start_streaming(handle_, &ctrl, &UvcCamera::frame_callback, this, 0);
  if (rc != UVC_SUCCESS) {
    close();
    *message = "camera " + device_name() + ": cannot start streaming: " + uvc_strerror(rc);
    return rc == UVC_ERROR_NO_DEVICE ? UvcOpenResult::kNoDevice : UvcOpenResult::kFailed;
  }
  *message = "streaming " + uvc_.format + " from " + device_name();
  return UvcOpenResult::kStreaming;
}

void UvcCamera::close() {
  if (handle_ != nullptr) {
    uvc_stop_streaming(handle_);
    uvc_close(handle_);
    handle_ = nullptr;
  }
  if (device_ != nullptr) {
    uvc_unref_device(device_);
    device_ = nullptr;
  }
  if (context_ != nullptr) {
    uvc_exit(context_);
    context_ = nullptr;
  }
}

std::string UvcCamera::last_error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return last_error_;
}

void UvcCamera::frame_callback(uvc_frame* frame, void* self) {
  static_cast<UvcCamera*>(self)->on_uvc_frame(*frame);
}

void UvcCamera::on_uvc_frame(const uvc_frame& frame) {
  const Intrinsics& in = camera_.intrinsics;
  const size_t pixels = static_cast<size_t>(in.width) * in.height;
  const int64_t frame_number = frames_seen_++;
  if (frame.width != static_cast<uint32_t>(in.width) || frame.height != static_cast<uint32_t>(in.height) ||
      frame.data_bytes != 2 * pixels) {
    ++frames_malformed_;
    std::lock_guard<std::mutex> lock(error_mutex_);
    last_error_ = "UVC frame dropped: " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                  ", " + std::to_string(frame.data_bytes) + " bytes, expected " + std::to_string(in.width) +
                  "x" + std::to_string(in.height) + ", " + std::to_string(2 * pixels) + " bytes";
    return;
  }
  std::vector<float> depth_m =
      raw16_to_distance_m(static_cast<const uint8_t*>(frame.data), pixels, uvc_.depth_unit_mm);
  if (uvc_.radial_distance) radial_to_z_.apply(&depth_m);
  const int64_t utime =
      static_cast<int64_t>(frame.capture_time.tv_sec) * 1000000 + frame.capture_time.tv_usec;
  on_frame_(std::move(depth_m), utime, frame_number);
}

}  // namespace tofguard::camera
