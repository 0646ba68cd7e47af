/* vmhaptics open HD API utilities: a three-component vector, laid out as
 * three values in a row so that hdGetDoublev(HD_CURRENT_POSITION, v) can
 * write straight into an hduVector3Dd. Header-only C++. */
#ifndef VMHAPTICS_HDU_VECTOR_H_
#define VMHAPTICS_HDU_VECTOR_H_

#ifdef __cplusplus

#include <cmath>
#include <ostream>

template <typename T>
class hduVector3D {
 public:
  typedef T EltType;

  hduVector3D() : v_{T(0), T(0), T(0)} {}
  hduVector3D(T x, T y, T z) : v_{x, y, z} {}
  explicit hduVector3D(const T* xyz) : v_{xyz[0], xyz[1], xyz[2]} {}
  template <typename U>
  explicit hduVector3D(const hduVector3D<U>& o)
      : v_{T(o[0]), T(o[1]), T(o[2])} {}

  // the components as an array, for hdGet...v / hdSet...v
  operator T*() { return v_; }
  operator const T*() const { return v_; }
  T& operator[](int i) { return v_[i]; }
  const T& operator[](int i) const { return v_[i]; }

  void set(T x, T y, T z) { v_[0] = x; v_[1] = y; v_[2] = z; }

  hduVector3D& operator+=(const hduVector3D& o) {
    for (int i = 0; i < 3; ++i) v_[i] += o.v_[i];
    return *this;
  }
  hduVector3D& operator-=(const hduVector3D& o) {
    for (int i = 0; i < 3; ++i) v_[i] -= o.v_[i];
    return *this;
  }
  hduVector3D& operator*=(T s) {
    for (int i = 0; i < 3; ++i) v_[i] *= s;
    return *this;
  }
  hduVector3D& operator/=(T s) {
    for (int i = 0; i < 3; ++i) v_[i] /= s;
    return *this;
  }
  hduVector3D operator-() const { return hduVector3D(-v_[0], -v_[1], -v_[2]); }

  T dotProduct(const hduVector3D& o) const {
    return v_[0] * o.v_[0] + v_[1] * o.v_[1] + v_[2] * o.v_[2];
  }
  hduVector3D crossProduct(const hduVector3D& o) const {
    return hduVector3D(v_[1] * o.v_[2] - v_[2] * o.v_[1],
                       v_[2] * o.v_[0] - v_[0] * o.v_[2],
                       v_[0] * o.v_[1] - v_[1] * o.v_[0]);
  }
  T magnitude() const { return T(std::sqrt(double(dotProduct(*this)))); }
  // unit length; a zero vector stays zero
  void normalize() {
    const T m = magnitude();
    if (m != T(0)) *this /= m;
  }
  bool isZero(T epsilon) const {
    return std::fabs(double(v_[0])) <= double(epsilon) &&
           std::fabs(double(v_[1])) <= double(epsilon) &&
           std::fabs(double(v_[2])) <= double(epsilon);
  }

 private:
  T v_[3];
};

template <typename T>
hduVector3D<T> operator+(hduVector3D<T> a, const hduVector3D<T>& b) {
  return a += b;
}
template <typename T>
hduVector3D<T> operator-(hduVector3D<T> a, const hduVector3D<T>& b) {
  return a -= b;
}
template <typename T, typename S>
hduVector3D<T> operator*(hduVector3D<T> a, S s) {
  return a *= T(s);
}
template <typename T, typename S>
hduVector3D<T> operator*(S s, hduVector3D<T> a) {
  return a *= T(s);
}
template <typename T, typename S>
hduVector3D<T> operator/(hduVector3D<T> a, S s) {
  return a /= T(s);
}
template <typename T>
bool operator==(const hduVector3D<T>& a, const hduVector3D<T>& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}
template <typename T>
bool operator!=(const hduVector3D<T>& a, const hduVector3D<T>& b) {
  return !(a == b);
}
template <typename T>
std::ostream& operator<<(std::ostream& os, const hduVector3D<T>& v) {
  return os << v[0] << " " << v[1] << " " << v[2];
}

typedef hduVector3D<double> hduVector3Dd;
typedef hduVector3D<float> hduVector3Df;
typedef hduVector3D<int> hduVector3Di;

#endif /* __cplusplus */

#endif /* VMHAPTICS_HDU_VECTOR_H_ */
