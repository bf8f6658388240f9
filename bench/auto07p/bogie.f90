!----------------------------------------------------------------------------------------------------------------------
! The two-axle bogie of include/hunting_monitor/bogie.h for AUTO-07p: our own encoding of its 13 equations with the
! defaults of config/bogie_default.yaml (MODEL.md's wheelsets, the simplified conicity fit, the smoothed flange force;
! the frame on air springs and yaw dampers in series with their joints, under a fixed carbody). The state in the
! scaled units of `hunting`'s continuation: displacements and the dampers' deflection in mm or mrad, rates in 0.1 m/s
! or 0.1 rad/s: U(1..4) leading wheelset y, y', psi, psi'; U(5..8) trailing; U(9..12) frame yf, yf', psif, psif';
! U(13) the yaw dampers' deflection u. PAR(1) = V [km/h], PAR(2) = Kx, PAR(3) = Ky [MN/m]; PAR(9) = max|y1| over a
! cycle [mm] (PVLS).
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
  DOUBLE PRECISION, PARAMETER :: MF = 2600D0, JF = 1800D0, B = 1.25D0, KSY = 2.5D5, CSY = 3D4
  DOUBLE PRECISION, PARAMETER :: KA = 1.5D5, DA = 1.0D0, CD = 1D6, KD = 5D7, DD = 1.3D0
  DOUBLE PRECISION :: V, KX, KY, KG, YF, YFD, PSIF, PSIFD, UD, Y, YD, PSI, PSID, LAMBDA, FT, Q, X, DAMPER
  DOUBLE PRECISION :: FY, MZ, YDD, PSIDD
  INTEGER :: I, O
  V = PAR(1) / 3.6D0
  KX = PAR(2) * 1D6
  KY = PAR(3) * 1D6
  KG = KX * (RATIO - 1D0)
  YF = U(9) * 1D-3
  YFD = U(10) * 0.1D0
  PSIF = U(11) * 1D-3
  PSIFD = U(12) * 0.1D0
  UD = U(13) * 1D-3
  FY = 0D0
  MZ = 0D0
  DO I = 1, 2
    O = 4 * (I - 1)
    X = B
    IF (I == 2) X = -B
    Y = U(O + 1) * 1D-3
    YD = U(O + 2) * 0.1D0
    PSI = U(O + 3) * 1D-3
    PSID = U(O + 4) * 0.1D0
    LAMBDA = 0.7D0 * EXP(-((Y - 0.01D0) / 0.00145D0)**2) + 0.7D0 * EXP(-((Y + 0.01D0) / 0.00145D0)**2) + 0.1358D0
    FT = ALPHA1 * Y**3 + ALPHA2 * Y**5
    Q = Y - YF - X * PSIF
    YDD = (-2D0 * CY / V * YD + 2D0 * CY * PSI - KG * Y - KY * Q - FT) / M
    PSIDD = (-2D0 * D0 * CX * LAMBDA / R0 * Y - 2D0 * D0**2 * CX / V * PSID - KX * D1**2 * (PSI - PSIF)) / YI
    F(O + 1) = YD * 1D3
    F(O + 2) = YDD * 10D0
    F(O + 3) = PSID * 1D3
    F(O + 4) = PSIDD * 10D0
    FY = FY + KY * Q
    MZ = MZ + X * KY * Q + KX * D1**2 * (PSI - PSIF)
  END DO
  DAMPER = KD * (DD * PSIF - UD)
  F(9) = YFD * 1D3
  F(10) = (FY - KSY * YF - CSY * YFD) / MF * 10D0
  F(11) = PSIFD * 1D3
  F(12) = (MZ - 2D0 * KA * DA**2 * PSIF - 2D0 * DD * DAMPER) / JF * 10D0
  F(13) = DAMPER / CD * 1D3
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
