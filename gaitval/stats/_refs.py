"""Full citations used in the statistics docstrings and table captions."""

QI2014 = ("Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of "
          "spatial-temporal gait parameters using a low-cost ultrasonic motion analysis "
          "system. Sensors 2014, 14(8), 15434-15457")
BLAND_ALTMAN_1999 = ("Bland, J.M.; Altman, D.G. Measuring agreement in method comparison "
                     "studies. Stat. Methods Med. Res. 1999, 8, 135-160")
MCGRAW_WONG_1996 = ("McGraw, K.O.; Wong, S.P. Forming inferences about some intraclass "
                    "correlation coefficients. Psychol. Methods 1996, 1(1), 30-46")
SHROUT_FLEISS_1979 = ("Shrout, P.E.; Fleiss, J.L. Intraclass correlations: uses in assessing "
                      "rater reliability. Psychol. Bull. 1979, 86(2), 420-428")
SINGLE2024 = ("Single, M.; Bruhin, L.C.; et al. A transferable lidar-based method to conduct "
              "contactless assessments of gait parameters in diverse home-like environments. "
              "Sensors 2024, 24(4), 1172")
