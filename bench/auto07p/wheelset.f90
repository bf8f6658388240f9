!----------------------------------------------------------------------------------------------------------------------
! The wheelset model of docs/MODEL.md (sections 2-3) for AUTO-07p: our own encoding of the four equations with the
! default CRH380 parameters, the simplified conicity fit and the smoothed flange force. The state in the scaled units
! of `hunting`'s continuation, so that AUTO's arclength weighs the same things: U(1) = y [mm], U(2) = dy/dt
! [0.1 m/s], U(3) = psi [mrad], U(4) = dpsi/dt [0.1 rad/s]; PAR(1) = V [km/h], PAR(2) = Kx, PAR(3) = Ky [MN/m];
! PAR(9) = max|y| over a cycle [mm] (PVLS), the amplitude `hunting cycles` reports.
!----------------------------------------------------------------------------------------------------------------------
SUBROUTINE FUNC(NDIM, U, ICP, PAR, IJAC, F, DFDU, DFDP)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM, ICP(*), IJAC
  DOUBLE PRECISION, INTENT(IN) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(OUT) :: F(NDIM)
  DOUBLE PRECISION, INTENT(INOUT) :: DFDU(NDIM, NDIM), DFDP(NDIM, *)
  DOUBLE PRECISION, PARAMETER :: M = 1869D0, YI = 910D0, D0 = 0.7465D0, D1 = 1.0D0, R0 = 0.43D0
  DOUBLE PRECISION, PARAMETER :: CX = 7.99D6, CY = 7.99D6, RATIO = 1.351186D0
  DOUBLE PRECISION, PARAMETER :: ALPHA1 = -1.6D11, ALPHA2 = 1.6D15
  DOUBLE PRECISION :: V, KX, KY, Y, LAMBDA, FT
  DOUBLE PRECISION :: YD, PSI, PSID, YDD, PSIDD
  V = PAR(1) / 3.6D0
  KX = PAR(2) * 1D6
  KY = PAR(3) * 1D6
  Y = U(1) * 1D-3
  YD = U(2) * 0.1D0
  PSI = U(3) * 1D-3
  PSID = U(4) * 0.1D0
  LAMBDA = 0.7D0 * EXP(-((Y - 0.01D0) / 0.00145D0)**2) + 0.7D0 * EXP(-((Y + 0.01D0) / 0.00145D0)**2) + 0.1358D0
  FT = ALPHA1 * Y**3 + ALPHA2 * Y**5
  YDD = -(KX / M) * (RATIO - 1D0) * Y - (KY / M) * Y - 2D0 * CY / (M * V) * YD + 2D0 * CY / M * PSI - FT / M
  PSIDD = -2D0 * D0 * CX * LAMBDA / (YI * R0) * Y - KX * D1**2 / YI * PSI - 2D0 * D0**2 * CX / (YI * V) * PSID
  F(1) = YD * 1D3
  F(2) = YDD * 10D0
  F(3) = PSID * 1D3
  F(4) = PSIDD * 10D0
END SUBROUTINE FUNC

SUBROUTINE STPNT(NDIM, U, PAR, T)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM
  DOUBLE PRECISION, INTENT(INOUT) :: U(NDIM), PAR(*)
  DOUBLE PRECISION, INTENT(IN) :: T
  U(1:NDIM) = 0D0
  PAR(1) = 300D0
  PAR(2) = 8.96D0
  PAR(3) = 8.96D0
END SUBROUTINE STPNT

SUBROUTINE PVLS(NDIM, U, PAR)
  IMPLICIT NONE
  INTEGER, INTENT(IN) :: NDIM
  DOUBLE PRECISION, INTENT(IN) :: U(NDIM)
  DOUBLE PRECISION, INTENT(INOUT) :: PAR(*)
  DOUBLE PRECISION, EXTERNAL :: GETP
  PAR(9) = MAX(ABS(GETP('MAX', 1, U)), ABS(GETP('MIN', 1, U)))
END SUBROUTINE PVLS

SUBROUTINE BCND
END SUBROUTINE BCND

SUBROUTINE ICND
END SUBROUTINE ICND

SUBROUTINE FOPT
END SUBROUTINE FOPT
