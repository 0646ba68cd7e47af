// A C++ client using the header-only HDU pieces (include/HDU/) as public
// programs do: the position read straight into an hduVector3Dd, the
// transform into an hduMatrix. Checks that they agree with each other and
// with closed forms; exit 1 on any failure.
#include <HD/hd.h>
#include <HDU/hduError.h>
#include <HDU/hduMatrix.h>
#include <HDU/hduVector.h>

#include <cmath>
#include <cstdio>

namespace {
int g_failed = 0;
void check(bool ok, const char* what) {
  if (!ok) {
    ++g_failed;
    std::fprintf(stderr, "FAILED: %s\n", what);
  }
}
}  // namespace

int main() {
  // vector algebra against closed forms
  const hduVector3Dd x(1, 0, 0), y(0, 1, 0);
  check(x.crossProduct(y) == hduVector3Dd(0, 0, 1), "x cross y = z");
  hduVector3Dd v(3, 4, 0);
  check(v.magnitude() == 5.0, "|(3,4,0)| = 5");
  v.normalize();
  check(std::fabs(v[0] - 0.6) < 1e-15 && std::fabs(v[1] - 0.8) < 1e-15,
        "normalize");
  check((2.0 * x + y - x) == hduVector3Dd(1, 1, 0), "sums and scaling");

  const HHD h = hdInitDevice(HD_DEFAULT_DEVICE);
  HDErrorInfo e = hdGetError();
  if (HD_DEVICE_ERROR(e)) {
    hduPrintError(stderr, &e, "hdInitDevice: ");
    return 1;
  }
  struct State {
    hduVector3Dd p;
    hduMatrix T;
  } st;
  hdStartScheduler();
  hdScheduleSynchronous(
      [](void* u) -> HDCallbackCode {
        auto* s = static_cast<State*>(u);
        hdBeginFrame(hdGetCurrentDevice());
        hdGetDoublev(HD_CURRENT_POSITION, s->p);
        hdGetDoublev(HD_CURRENT_TRANSFORM, s->T);
        hdEndFrame(hdGetCurrentDevice());
        return HD_CALLBACK_DONE;
      },
      &st, HD_DEFAULT_SCHEDULER_PRIORITY);
  hdStopScheduler();
  const hduVector3Dd& p = st.p;
  const hduMatrix& T = st.T;
  check(!HD_DEVICE_ERROR(hdGetError()), "state reads");
  check(p.magnitude() > 1.0, "a position away from the origin");
  check(T.getTranslation() == p, "the transform's translation is the position");
  hduVector3Dd o;
  T.multVecMatrix(hduVector3Dd(0, 0, 0), o);
  check(o == p, "the origin maps to the position");
  // the rotation part is orthonormal: rows of m[0..2][0..2] unit and
  // mutually orthogonal
  for (int i = 0; i < 3; ++i) {
    const hduVector3Dd r(T(i, 0), T(i, 1), T(i, 2));
    check(std::fabs(r.magnitude() - 1.0) < 1e-9, "unit rotation row");
    const hduVector3Dd s(T((i + 1) % 3, 0), T((i + 1) % 3, 1), T((i + 1) % 3, 2));
    check(std::fabs(r.dotProduct(s)) < 1e-9, "orthogonal rotation rows");
  }
  const hduMatrix twice = T.multRight(hduMatrix());
  check(twice.getTranslation() == p, "times the identity");
  hdDisableDevice(h);
  std::printf("hdu_client: position %.3f %.3f %.3f mm, %d failed\n", p[0], p[1],
              p[2], g_failed);
  return g_failed == 0 ? 0 : 1;
}
