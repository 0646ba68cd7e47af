/* vmhaptics open HD API utilities: a 4x4 transform in the layout
 * HD_CURRENT_TRANSFORM has. The 16 doubles are the OpenGL column-major
 * matrix; read in order into m[4][4] they give the row-vector form, with
 * the rotation's columns as rows and the translation (mm) in the last row:
 * m[3][0..2]. Header-only C++. */
#ifndef VMHAPTICS_HDU_MATRIX_H_
#define VMHAPTICS_HDU_MATRIX_H_

#ifdef __cplusplus

#include <HDU/hduVector.h>

class hduMatrix {
 public:
  hduMatrix() { makeIdentity(); }
  // 16 values in HD_CURRENT_TRANSFORM's order
  explicit hduMatrix(const double* v16) { set(v16); }

  void set(const double* v16) {
    for (int i = 0; i < 16; ++i) m_[i / 4][i % 4] = v16[i];
  }
  void get(double* v16) const {
    for (int i = 0; i < 16; ++i) v16[i] = m_[i / 4][i % 4];
  }
  void makeIdentity() {
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m_[r][c] = r == c ? 1.0 : 0.0;
  }
  // the storage in HD's order, for hdGetDoublev(HD_CURRENT_TRANSFORM, m)
  operator double*() { return &m_[0][0]; }
  operator const double*() const { return &m_[0][0]; }
  double& operator()(int row, int col) { return m_[row][col]; }
  double operator()(int row, int col) const { return m_[row][col]; }

  // translation, mm
  hduVector3Dd getTranslation() const {
    return hduVector3Dd(m_[3][0], m_[3][1], m_[3][2]);
  }
  // the product this * o in the row-vector form (o applied after this)
  hduMatrix multRight(const hduMatrix& o) const {
    hduMatrix r;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double s = 0.0;
        for (int k = 0; k < 4; ++k) s += m_[i][k] * o.m_[k][j];
        r.m_[i][j] = s;
      }
    return r;
  }
  // a point (mm) through the transform: p' = p R + t in the row-vector form
  void multVecMatrix(const hduVector3Dd& p, hduVector3Dd& out) const {
    hduVector3Dd r;
    for (int j = 0; j < 3; ++j)
      r[j] = p[0] * m_[0][j] + p[1] * m_[1][j] + p[2] * m_[2][j] + m_[3][j];
    out = r;
  }
  // a direction through the rotation alone
  void multDirMatrix(const hduVector3Dd& d, hduVector3Dd& out) const {
    hduVector3Dd r;
    for (int j = 0; j < 3; ++j)
      r[j] = d[0] * m_[0][j] + d[1] * m_[1][j] + d[2] * m_[2][j];
    out = r;
  }

 private:
  double m_[4][4];
};

#endif /* __cplusplus */

#endif /* VMHAPTICS_HDU_MATRIX_H_ */
